"""Shared helpers of the Python benchmarks (benches/python/, run by hand; docs/python.md
has the figures and how they were measured)."""

import os
import pathlib
import resource
import time

ROOT = pathlib.Path(__file__).resolve().parents[2]


def load():
    """The machine's load averages (1, 5, 15 min) and its core count, for the record."""
    return os.getloadavg(), os.cpu_count()


def cpu_self():
    """CPU seconds (user + system) of this process so far, every thread counted."""
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def cpu_children():
    """CPU seconds (user + system) of this process's waited-for children so far."""
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


class Measure:
    """Wall and CPU seconds of a block: `with Measure() as m: ...; m.wall, m.cpu`."""

    def __init__(self, children=False):
        self.children = children

    def _cpu(self):
        return cpu_children() if self.children else cpu_self()

    def __enter__(self):
        self.w0, self.c0 = time.perf_counter(), self._cpu()
        return self

    def __exit__(self, *exc):
        self.wall = time.perf_counter() - self.w0
        self.cpu = self._cpu() - self.c0
        return False


def header(what):
    (l1, l5, l15), n = load()
    print(f"# {what}")
    print(f"# load average {l1:.2f} {l5:.2f} {l15:.2f} on {n} cores (before)")
