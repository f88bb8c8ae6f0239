"""mecano: flexible multibody dynamics (mecano-rs) from Python.

Decks, runs into memory or into the command line's files, the histories as NumPy arrays
(or pandas DataFrames), linearised modes, and a simulation you drive step by step with
inputs that close control loops. Units are SI throughout: m, rad, s, kg, N, N·m, J.

    import mecano
    deck = mecano.Deck.read("decks/pendulum.dat")
    run = mecano.run(deck.with_parameters(E=2.1e10))
    node = run.node(12)              # a History: node.t, node["x"], node.to_pandas()
"""

from __future__ import annotations

import json
import os
from typing import Any, Callable, Dict, Iterator, List, Optional, Sequence, Union

import numpy as np

from . import _mecano
from ._mecano import (
    Deck,
    DeckError,
    MecanoError,
    Sensors,
    SimulationError,
    __version__,
)

__all__ = [
    "Deck",
    "DeckError",
    "History",
    "MecanoError",
    "Run",
    "Sensors",
    "Simulation",
    "SimulationError",
    "__version__",
    "modes",
    "open",
    "run",
    "run_many",
]

PathLike = Union[str, "os.PathLike[str]"]


class History:
    """One history: a file's columns (``t`` first) and its rows.

    ``h.t`` and ``h["x"]`` (or ``h.x``) are NumPy arrays (views of ``h.array``, no copy);
    ``h.columns`` names them; ``h.to_pandas()`` is a DataFrame indexed by ``t`` (pandas
    is not a dependency: it is imported then). Units: SI (m, rad, m/s, rad/s, N, N·m, J).
    """

    __slots__ = ("columns", "array", "name")

    def __init__(self, columns: Sequence[str], array: np.ndarray, name: str = "") -> None:
        self.columns: List[str] = list(columns)
        self.array: np.ndarray = array
        self.name: str = name

    @property
    def t(self) -> np.ndarray:
        """Times, s."""
        return self.array[:, 0]

    def __getitem__(self, column: str) -> np.ndarray:
        try:
            k = self.columns.index(column)
        except ValueError:
            raise KeyError(
                f"{self.name or 'this history'} has no column {column!r}; its columns: "
                + ", ".join(self.columns)
            ) from None
        return self.array[:, k]

    def __getattr__(self, column: str) -> np.ndarray:
        if column.startswith("_"):
            raise AttributeError(column)
        try:
            return self[column]
        except KeyError as e:
            raise AttributeError(str(e)) from None

    def __contains__(self, column: object) -> bool:
        return column in self.columns

    def __iter__(self) -> Iterator[str]:
        return iter(self.columns)

    def __len__(self) -> int:
        return int(self.array.shape[0])

    def keys(self) -> List[str]:
        """The column names."""
        return list(self.columns)

    def to_pandas(self) -> Any:
        """A pandas DataFrame of the columns, indexed by ``t`` (needs pandas)."""
        try:
            import pandas as pd
        except ImportError as e:
            raise ImportError(
                "History.to_pandas() needs pandas (pip install pandas); the arrays are h[column]"
            ) from e
        frame = pd.DataFrame(self.array[:, 1:], columns=self.columns[1:])
        frame.index = pd.Index(self.array[:, 0], name="t")
        return frame

    def __repr__(self) -> str:
        return f"History({self.name!r}, {len(self)} rows, columns={self.columns})"


class Run:
    """A run's histories and summary, in memory or in an output directory.

    ``run.node(12)``, ``run.element(23)``, ``run.energy`` are :class:`History` objects
    (``frame=True``: a pandas DataFrame); ``run.summary`` is ``summary.json`` as a dict;
    ``run.complete`` says whether it reached its end time; ``run.failure`` is the
    diagnosis of a failed run (None otherwise).
    """

    def __init__(self, data: "_mecano.RunData") -> None:
        self._data = data
        self._summary: Optional[Dict[str, Any]] = None

    def node(self, node: int, frame: bool = False) -> Any:
        """Node ``node``'s history: t, x, y, z (m), ux, uy, uz (m), rx, ry, rz (rad,
        rotation vector), vx, vy, vz (m/s), wx, wy, wz (rad/s), ax, ay, az (m/s²)."""
        columns, array = self._data.node(_int("node", node))
        h = History(columns, array, f"node {node}")
        return h.to_pandas() if frame else h

    def element(self, element: int, frame: bool = False) -> Any:
        """Element ``element``'s history (its own columns: a joint's angle and reaction,
        a beam's resultants, an input's value...)."""
        columns, array = self._data.element(_int("element", element))
        h = History(columns, array, f"element {element}")
        return h.to_pandas() if frame else h

    @property
    def energy(self) -> History:
        """The energy balance (J): kinetic, strain, gravity, total, external_work,
        damping_dissipation, numerical_dissipation, balance_residual."""
        columns, array = self._data.energy()
        return History(columns, array, "energy")

    @property
    def nodes(self) -> List[int]:
        """Numbers of the nodes with a history."""
        return list(self._data.node_ids)

    @property
    def elements(self) -> List[int]:
        """Numbers of the elements with a history."""
        return list(self._data.element_ids)

    @property
    def summary(self) -> Dict[str, Any]:
        """``summary.json`` as a dict (counters, CPU seconds, energy balance, failure)."""
        if self._summary is None:
            self._summary = json.loads(self._data.summary_json)
        return self._summary

    @property
    def complete(self) -> bool:
        """Whether the run reached its end time."""
        return bool(self.summary.get("complete", False))

    @property
    def failure(self) -> Optional[str]:
        """The failure's diagnosis (where, when, why), or None."""
        f = self.summary.get("failure")
        return None if f is None else str(f.get("message", f))

    @property
    def time(self) -> float:
        """Time reached, s."""
        return float(self.summary.get("time_reached", 0.0))

    @property
    def dir(self) -> Optional[str]:
        """The output directory (None for a run into memory)."""
        d = self._data.dir
        return None if d is None else str(d)

    def __repr__(self) -> str:
        where = self.dir or "memory"
        state = "complete" if self.complete else "incomplete"
        return f"Run({self.summary.get('deck')!r}, {state}, t={self.time}, in {where})"


def _int(what: str, v: Any) -> int:
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
        raise TypeError(f"{what} is a number (int), not {type(v).__name__}")
    return int(v)


def _wrap_partial(e: BaseException) -> BaseException:
    data = getattr(e, "run_data", None)
    if data is not None:
        e.run = [Run(d) for d in data] if isinstance(data, list) else Run(data)  # type: ignore[attr-defined]
    return e


def run(
    deck: Union[Deck, PathLike],
    out: Optional[PathLike] = None,
    *,
    progress: Optional[Callable[[float, float], Any]] = None,
) -> Run:
    """Runs a deck (a :class:`Deck` or a path) as ``mecano-rs DECK`` does.

    ``out=None``: nothing is written; the histories stay in memory. ``out=dir``: the
    same files as the command line, byte for byte (but for the CPU seconds of
    summary.json), the directory claimed as the CLI claims it. ``progress(t, end)`` is
    called at most every 50 ms of wall time (s of simulated time). The GIL is released
    while the run computes. Ctrl-C stops it at the end of a step and raises
    KeyboardInterrupt whose ``run`` attribute holds the histories so far (incomplete).
    A failed run is returned (``run.complete`` False, ``run.failure`` the diagnosis).
    """
    try:
        return Run(_mecano.run_deck(deck, None if out is None else os.fspath(out), progress))
    except BaseException as e:
        raise _wrap_partial(e)


def run_many(
    decks: Sequence[Union[Deck, PathLike]],
    threads: Optional[int] = None,
    out: Optional[Sequence[Optional[PathLike]]] = None,
) -> List[Run]:
    """Runs several decks on ``threads`` threads (default: every core), the GIL
    released; returns the runs in the order of the decks (each as ``run`` would).
    Ctrl-C stops every run at the end of its step; the KeyboardInterrupt carries the
    runs so far in its ``run`` attribute (a list)."""
    outs = None if out is None else [None if o is None else os.fspath(o) for o in out]
    try:
        return [Run(d) for d in _mecano.run_many(list(decks), threads, outs)]
    except BaseException as e:
        raise _wrap_partial(e)


def open(dir: PathLike) -> Run:  # noqa: A001 - the package's reader of output directories
    """The run in an output directory written by mecano-rs or ``run(deck, out=dir)``
    (CSV files or ``FORMAT NETCDF``'s histories.nc)."""
    return Run(_mecano.open_dir(os.fspath(dir)))


def modes(
    deck: Union[Deck, PathLike],
    at: Union[None, str, float] = None,
    count: int = 20,
    rotating: bool = False,
) -> Dict[str, Any]:
    """The lowest ``count`` linearised modes of a deck, as ``mecano-rs modes`` computes
    them: about the initial state (``at=None``), the static equilibrium
    (``at="static"``), the state a run reaches at time ``at`` (s), or a hub's relative
    equilibrium in its rotating frame (``rotating=True``).

    Returns a dict: ``frequency_hz`` (damped, Hz), ``natural_hz`` (Hz),
    ``damping_ratio``, ``eigenvalue_real``/``eigenvalue_imag`` (1/s), ``kind``
    ("rigid", "elastic", "unstable"), ``shapes`` (modes × nodes × 6: displacements and
    rotations per node, in the order of ``nodes``), ``nodes``, ``groups``,
    ``highest_hz`` (the mesh's highest frequency) and ``time`` (s).
    """
    return dict(_mecano.modes(deck, at, count, rotating))


class Simulation(_mecano.Simulation):
    """A simulation of a deck you advance yourself.

    ``sim.step()`` takes one accepted step, ``sim.advance(t)`` steps until ``t`` (s),
    landing on it; ``sim.t`` is the time reached. Between steps read any node's
    ``position``, ``displacement``, ``rotation`` (matrix), ``velocity``,
    ``angular_velocity``, ``acceleration``, a HINGE's ``joint_angle`` (rad, turns
    counted) and ``joint_rate`` (rad/s), an element's outputs (``element``) and a
    joint's ``reaction`` (N, N·m). ``sim.run()`` gives the histories so far.

    Inputs (before the first step): ``add_input(hinge=3)`` is a torque about HINGE 3's
    axis (N·m), ``add_input(node=12, axis=1)`` a force along global y (N). Its value is

    * held over each step and set between steps by ``set_input(id, value)``, or by a
      law ``law(t, sim)`` called before each step (``tangent="explicit"``): a zero-order
      hold, first-order accurate in time when the value follows the state;
    * or a law ``law(t, s)`` called inside the step at every Newton iterate with ``s`` a
      :class:`Sensors` view of the declared ``sensors`` (``tangent="differentiated"``):
      its derivatives, by forward differences (one more call per sensor when the
      iteration matrix is rebuilt), enter the iteration matrix, and the scheme keeps its
      order (HHT: 2).

    The deck's own loads and drivers, between steps: ``set_load(k, s)`` holds the k-th
    FORCE/MOMENT card's time function at ``s`` (the load is ``s`` times the card's
    components, N or N·m; ``None`` gives the card its f(t) back; the accelerations restart
    from the new load, so the scheme keeps its order across the switch);
    ``set_drive(e, value, over=T)`` sends a driven HINGE/PRISMATIC or a PRESCRIBED
    element ``e`` to ``value`` (rad or m) over ``T`` s along the C² quintic from its
    present value, rate and acceleration, then holds it (a jump, ``T = 0`` while the law
    moves or is elsewhere, is refused: a prescribed motion needs a continuous velocity).

    ``sim.save(dir)`` writes a checkpoint and, beside it, ``simulation.json``: the values
    set on loads, drivers and held inputs; ``Simulation.load(dir)`` goes on from them (a
    record of another time than the checkpoint's is refused).
    """

    def run(self) -> Run:
        """The histories so far (the deck's OUTPUT selection) and the summary."""
        return Run(self.run_data())
