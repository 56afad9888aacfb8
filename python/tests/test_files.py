"""The package's file reading and writing go through libcf's file safety, as the tools do
(docs/bad-input.md): ReplayResult.to_csv and cf.read_trajectory."""

import os
import shutil
import subprocess
import sys

import pytest

import cf
from conftest import DATA

TRAJECTORY = DATA / "trajectories" / "cube_lblock_corner.csv"
HEADER = "t,tx,ty,tz,qw,qx,qy,qz\n"


@pytest.fixture()
def result_and_graph(tmp_path):
    """A short replay of a graph loaded from a copy in tmp_path, and that copy's path."""
    graph_path = tmp_path / "g.json"
    shutil.copy(DATA / "graphs" / "cube_l_block.json", graph_path)
    g = cf.load_graph(graph_path)
    t, p, q = cf.read_trajectory(TRAJECTORY)
    return cf.replay(g, t[:40], p[:40], q[:40]), graph_path


def test_file_errors_are_both_cf_errors_and_os_errors(tmp_path):
    assert issubclass(cf.FileError, cf.Error) and issubclass(cf.FileError, OSError)
    with pytest.raises(OSError, match=r"^reading '.*missing\.json': cannot open: no such file$"):
        cf.load_graph(tmp_path / "missing.json")
    with pytest.raises(cf.FileError):
        cf.read_trajectory(tmp_path / "missing.csv")
    bad = tmp_path / "bad.json"
    bad.write_text("{")
    with pytest.raises(cf.Error) as e:  # the file opens: its content is the problem
        cf.load_graph(bad)
    assert not isinstance(e.value, OSError)


def test_to_csv_never_writes_over_the_graph(result_and_graph):
    r, graph_path = result_and_graph
    before = graph_path.read_bytes()
    with pytest.raises(cf.FileError, match=r"^writing '.*g\.json': is an input of this run; refusing to overwrite it$"):
        r.to_csv(graph_path)
    assert graph_path.read_bytes() == before


def test_to_csv_refuses_special_files_without_blocking(result_and_graph, tmp_path):
    r, _ = result_and_graph
    fifo = tmp_path / "out.fifo"
    os.mkfifo(fifo)
    with pytest.raises(cf.Error, match=r"is a FIFO \(named pipe\); output files must be regular files$"):
        r.to_csv(fifo)
    with pytest.raises(cf.Error, match=r"^writing '/dev/full': is a character device"):
        r.to_csv("/dev/full")
    with pytest.raises(cf.Error, match=r"the directory '.*no/such' does not exist$"):
        r.to_csv(tmp_path / "no" / "such" / "o.csv")
    out = tmp_path / "o.csv"
    assert r.to_csv(out) == out.read_text()
    assert [p.name for p in tmp_path.iterdir() if ".tmp" in p.name] == []


def test_read_trajectory_refuses_special_files_without_blocking(tmp_path):
    fifo = tmp_path / "in.fifo"
    os.mkfifo(fifo)
    with pytest.raises(cf.Error, match=r"in\.fifo: cannot open the trajectory: is a FIFO \(named pipe\)"):
        cf.read_trajectory(fifo)
    with pytest.raises(cf.Error, match=r"^/dev/zero: cannot open the trajectory: is a character device"):
        cf.read_trajectory("/dev/zero")


@pytest.mark.parametrize("row, why", [
    ("0,1,2,nan,1,0,0,0", r"p\.csv:2: column 'tz' is not a finite number: 'nan'"),
    ("0,1,2,inf,1,0,0,0", r"p\.csv:2: column 'tz' is not a finite number: 'inf'"),
    ("0,1_000,2,3,1,0,0,0", r"p\.csv:2: column 'tx' is not a finite number: '1_000'"),
    ("0,0x1p4,2,3,1,0,0,0", r"p\.csv:2: column 'tx' is not a decimal number: '0x1p4'"),
    ("0.5,1,2,3,1,0,0,0\n0.4,1,2,3,1,0,0,0", r"p\.csv:3: time 0\.4 s does not increase"),
])
def test_read_trajectory_refuses_what_cfreplay_refuses(tmp_path, row, why):
    path = tmp_path / "p.csv"
    path.write_text(HEADER + row + "\n")
    with pytest.raises(cf.Error, match=why):
        cf.read_trajectory(path)


def test_quaternions_are_returned_as_written(tmp_path):
    path = tmp_path / "p.csv"
    path.write_text(HEADER + "0,1,2,3,-0.7071,0,0,0.7071\n")
    t, p, q = cf.read_trajectory(path)
    assert t.tolist() == [0.0] and p.tolist() == [[1.0, 2.0, 3.0]]
    assert q.tolist() == [[-0.7071, 0.0, 0.0, 0.7071]]


def test_numbers_keep_a_decimal_point_in_a_comma_locale(tmp_path):
    # A de_DE locale compiled into tmp_path (LOCPATH), so that the test needs no installed one.
    localedef = shutil.which("localedef")
    if localedef is None or subprocess.run([localedef, "-i", "de_DE", "-f", "UTF-8",
                                            str(tmp_path / "de_DE.UTF-8")]).returncode not in (0, 1):
        pytest.skip("localedef cannot build de_DE here")
    code = ("import locale, cf\n"
            "locale.setlocale(locale.LC_ALL, 'de_DE.UTF-8')\n"
            "assert locale.localeconv()['decimal_point'] == ','\n"
            f"g = cf.load_graph({str(DATA / 'graphs' / 'cube_l_block.json')!r})\n"
            f"t, p, q = cf.read_trajectory({str(TRAJECTORY)!r})\n"
            "print(cf.replay(g, t[:40], p[:40], q[:40]).to_csv(), end='')\n")
    env = dict(os.environ, LOCPATH=str(tmp_path))
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    rows = out.stdout.splitlines()
    header = rows[0].split(",")
    assert len(rows) == 41
    assert all(len(line.split(",")) == len(header) for line in rows[1:])
    assert rows[1].startswith("0,")  # the time's shortest round-trip decimal
