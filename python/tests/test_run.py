import filecmp
import json
import subprocess

import numpy as np
import pytest

import mecano

SHORT = "decks/driven_arm.dat"


def short_deck(root, end=0.3):
    text = (root / SHORT).read_text().replace("END 2.0", f"END {end}")
    return mecano.Deck(text, name=SHORT)


def test_memory_run_histories_and_summary(root):
    run = mecano.run(short_deck(root))
    assert run.complete and run.failure is None and run.dir is None
    assert run.nodes == [2] and run.elements == [1]
    node = run.node(2)
    assert node.columns[:4] == ["t", "x", "y", "z"]
    assert len(node) == 301 and node.t[-1] == pytest.approx(0.3)
    # The arm's radius stays 1 m (a hinge): x^2 + y^2 = 1 to the constraint tolerance.
    r = np.hypot(node["x"], node.y)
    assert np.max(np.abs(r - 1.0)) < 1e-9
    assert run.summary["stats"]["steps"] == 300
    assert "kinetic" in run.energy
    with pytest.raises(KeyError):
        run.node(99)
    with pytest.raises(TypeError):
        run.node("2")


def test_out_dir_writes_the_cli_files_byte_for_byte(root, tmp_path, cli):
    deck_path = tmp_path / "arm.dat"
    deck_path.write_text(short_deck(root).text)
    py_dir, cli_dir = tmp_path / "py", tmp_path / "cli"
    run = mecano.run(mecano.Deck.read(deck_path), out=py_dir)
    subprocess.run([cli, str(deck_path), "-o", str(cli_dir), "--quiet"], check=True)
    for name in ["node_2.csv", "element_1.csv", "energy.csv"]:
        assert filecmp.cmp(py_dir / name, cli_dir / name, shallow=False), name
    a = json.loads((py_dir / "summary.json").read_text())
    b = json.loads((cli_dir / "summary.json").read_text())
    a["stats"]["cpu_seconds"] = b["stats"]["cpu_seconds"] = 0
    assert a == b
    # The run read back from its directory, and mecano.open of the CLI's: the same numbers.
    opened = mecano.open(cli_dir)
    assert np.array_equal(opened.node(2).array, run.node(2).array)
    memory = mecano.run(mecano.Deck.read(deck_path))
    assert np.array_equal(memory.node(2).array, run.node(2).array)
    assert np.array_equal(memory.element(1).array, opened.element(1).array)


def test_open_reads_netcdf_runs(root, tmp_path):
    text = short_deck(root).text.replace("EVERY 1", "EVERY 1 FORMAT NETCDF")
    run = mecano.run(mecano.Deck(text, name="nc.dat"), out=tmp_path / "nc")
    assert (tmp_path / "nc" / "histories.nc").exists()
    memory = mecano.run(mecano.Deck(text, name="nc.dat"))
    assert np.array_equal(mecano.open(tmp_path / "nc").node(2).array, memory.node(2).array)
    assert run.nodes == [2]


def test_pandas_frame_when_installed(root):
    pd = pytest.importorskip("pandas")
    frame = mecano.run(short_deck(root, 0.05)).node(2, frame=True)
    assert isinstance(frame, pd.DataFrame) and frame.index.name == "t"


def test_failed_run_keeps_its_histories(root):
    run = mecano.run(root / "decks" / "stab_diverge.dat")
    assert not run.complete
    assert run.failure
    assert len(run.energy) >= 1


def test_progress_callback_and_its_exception(root):
    seen = []
    mecano.run(short_deck(root, 0.3), progress=lambda t, end: seen.append((t, end)))
    assert all(end == 0.3 for _, end in seen)

    def boom(t, end):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here") as e:
        mecano.run(mecano.Deck.read(root / "decks" / "pendulum.dat"), progress=boom)
    assert not e.value.run.complete and len(e.value.run.energy) >= 1


def test_run_many_equals_serial_runs(root):
    decks = [short_deck(root, 0.1).with_parameters(A=a) for a in (1.0, 2.0, 3.0, 3.1)]
    parallel = mecano.run_many(decks, threads=4)
    serial = [mecano.run(d) for d in decks]
    for p, s in zip(parallel, serial):
        assert np.array_equal(p.node(2).array, s.node(2).array)
        assert np.array_equal(p.element(1).array, s.element(1).array)


def test_modes_are_the_cli_numbers(root, tmp_path, cli):
    deck = root / "decks" / "cantilever_modes.dat"
    m = mecano.modes(deck, count=4)
    subprocess.run([cli, "modes", str(deck), "--count", "4", "-o", str(tmp_path), "--quiet"], check=True)
    lines = (tmp_path / "modes.csv").read_text().splitlines()
    header = lines[0].split(",")
    k = header.index("frequency_hz")
    cli_hz = [float(l.split(",")[k]) for l in lines[1:]]
    assert np.array_equal(m["frequency_hz"], np.array(cli_hz))
    assert m["shapes"].shape == (4, len(m["nodes"]), 6)


def test_a_thread_pool_of_runs_equals_serial_runs(root):
    """mecano.run on a ThreadPoolExecutor (the GIL released): the serial histories."""
    from concurrent.futures import ThreadPoolExecutor

    decks = [short_deck(root, 0.1).with_parameters(A=a) for a in (1.0, 2.0, 3.0, 3.1)]
    with ThreadPoolExecutor(4) as pool:
        threaded = list(pool.map(mecano.run, decks))
    for d, p in zip(decks, threaded):
        s = mecano.run(d)
        assert np.array_equal(p.node(2).array, s.node(2).array)
        assert np.array_equal(p.energy.array, s.energy.array)


@pytest.mark.parametrize(
    "call, error",
    [
        (lambda r: mecano.run(r / "decks" / "driven_arm.dat", out=3), TypeError),
        (lambda r: mecano.run(r / "decks" / "driven_arm.dat", progress=3), TypeError),
        (lambda r: mecano.run_many([r / "decks" / "driven_arm.dat"], out=[]), ValueError),
        (lambda r: mecano.run_many([3]), TypeError),
        (lambda r: mecano.modes(r / "decks" / "cantilever_modes.dat", at=float("nan")), ValueError),
        (lambda r: mecano.modes(r / "decks" / "cantilever_modes.dat", at=[1]), TypeError),
        (lambda r: mecano.modes(r / "decks" / "cantilever_modes.dat", count=0), ValueError),
        (lambda r: mecano.open(r / "decks"), mecano.MecanoError),
    ],
)
def test_bad_arguments_of_runs_raise_python_exceptions(root, call, error):
    with pytest.raises(error):
        call(root)
