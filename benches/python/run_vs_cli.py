"""Issue 36 target: `mecano.run` on decks/pendulum.dat costs at most 3 % more CPU than the
command line (`mecano-rs decks/pendulum.dat`).

Measured: the CPU seconds (user + system, getrusage) of
  * the CLI, a child process writing its files into a scratch directory (its whole
    process: start, parse, run, files);
  * `mecano.run(path)` into memory and `mecano.run(path, out=dir)` into the CLI's files,
    in this process (the interpreter's start and `import mecano` not counted: they are
    paid once per session, not per run).
Each is repeated REPEAT times, interleaved, and the minimum kept (the machine may be
shared: the minimum is the run least disturbed). Needs a release wheel installed
(`pip install ./python`) and the release binary (`cargo build --release`).

    python benches/python/run_vs_cli.py [--repeat 3] [--bin target/release/mecano-rs]
"""

import argparse
import subprocess
import tempfile

import mecano

from common import ROOT, Measure, header, load


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--bin", default=str(ROOT / "target" / "release" / "mecano-rs"))
    ap.add_argument("--deck", default=str(ROOT / "decks" / "pendulum.dat"))
    a = ap.parse_args()
    header(f"mecano.run vs the CLI on {a.deck}")
    cli, mem, files, steps = [], [], [], set()
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(a.repeat):
            with Measure(children=True) as m:
                subprocess.run([a.bin, a.deck, "-o", f"{tmp}/cli", "--quiet"], check=True)
            cli.append(m.cpu)
            with Measure() as m:
                r = mecano.run(a.deck)
            mem.append(m.cpu)
            steps.add(r.summary["stats"]["steps"])
            with Measure() as m:
                r = mecano.run(a.deck, out=f"{tmp}/py")
            files.append(m.cpu)
            steps.add(r.summary["stats"]["steps"])
            print(f"  round {k + 1}: CLI {cli[-1]:.3f} s, run() into memory {mem[-1]:.3f} s, "
                  f"run(out=dir) {files[-1]:.3f} s CPU")
    assert len(steps) == 1, steps
    c = min(cli)
    print(f"steps per run: {steps.pop()}")
    print(f"CLI (whole process)      min {c:.3f} s CPU")
    print(f"mecano.run(deck)         min {min(mem):.3f} s CPU  ({100 * (min(mem) / c - 1):+.1f} %)")
    print(f"mecano.run(deck, out=d)  min {min(files):.3f} s CPU  ({100 * (min(files) / c - 1):+.1f} %)")
    (l1, l5, l15), n = load()
    print(f"# load average {l1:.2f} {l5:.2f} {l15:.2f} on {n} cores (after)")


if __name__ == "__main__":
    main()
