"""``acld-gym reproduce --plots DIR --json PATH`` writes its figures and table all or none
(issue 65, a second probe: a full disk after the first figure left one new figure among
the old ones); :func:`acld_gym.util.atomic.write_files`."""

import os
import subprocess
import sys
import textwrap

import pytest

from acld_gym.util.atomic import write_files


def test_write_files_is_all_or_none(tmp_path):
    (tmp_path / "a.txt").write_text("old a")
    (tmp_path / "blocker").write_text("a file, not a folder")
    with pytest.raises(OSError):
        write_files({tmp_path / "a.txt": b"new a", tmp_path / "blocker" / "b.txt": b"new b"})
    assert (tmp_path / "a.txt").read_text() == "old a"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt", "blocker"]  # no temporary
    assert write_files({tmp_path / "a.txt": b"new a"}) == [tmp_path / "a.txt"]
    assert (tmp_path / "a.txt").read_bytes() == b"new a"


SCRIPT = textwrap.dedent(
    """
    import resource, sys
    from acld_gym.thesis.cli import main
    resource.setrlimit(resource.RLIMIT_FSIZE, (int(sys.argv[1]), resource.RLIM_INFINITY))
    sys.exit(main(["reproduce", "--quiet", "--t-end", "0.05", "--plots", sys.argv[2],
                   "--json", sys.argv[3]]))
    """
)


def test_a_full_disk_leaves_every_old_output_and_no_new_one(tmp_path):
    plots, table = tmp_path / "plots", tmp_path / "table.json"
    plots.mkdir()
    old = {plots / "hankel_singular_values.png": b"old", plots / "case1_lqr_sat.png": b"old"}
    old[table] = b"old"
    for path, data in old.items():
        path.write_bytes(data)
    # the Hankel figure (~25 kB) fits under 40 kB; the frequency response (~60 kB) does not
    env = dict(os.environ, OMP_NUM_THREADS="1")
    run = subprocess.run(
        [sys.executable, "-c", SCRIPT, str(40_000), str(plots), str(table)],
        capture_output=True,
        text=True,
        timeout=300,
        env=env,
    )
    assert run.returncode == 1, run.stderr
    assert run.stderr.strip().endswith("File too large") and "Traceback" not in run.stderr
    assert {p: p.read_bytes() for p in old} == old
    assert sorted(p.name for p in plots.iterdir()) == sorted(p.name for p in old if p != table)
    # The same command with room writes all 20 figures and the table over old ones:
    # tests/thesis/test_cli.py's reproduce_out, in-process (a second interpreter here drew
    # the 20 figures again, ~6 s of CPU), and test_write_files_is_all_or_none above.
