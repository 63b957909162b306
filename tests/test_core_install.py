"""The core install's jobs (``.ci/core_install_check.py``: every id, the evaluator without
MPC, every shipped agent with numpy only), run here with the extras' imports blocked and
from a directory outside the checkout; ``.ci/run`` runs the same script in a clean venv
with the built wheel."""

from __future__ import annotations

from pathlib import Path

from tests.core_only import run_core_only

SCRIPT = Path(__file__).resolve().parents[1] / ".ci" / "core_install_check.py"


def test_core_install_runs_envs_baselines_and_agents(tmp_path):
    code = f"import runpy; runpy.run_path({str(SCRIPT)!r}, run_name='__main__')"
    out = run_core_only(code, cwd=tmp_path)
    assert out.returncode == 0, out.stdout + out.stderr
    lines = out.stdout.splitlines()
    assert lines[-1] == "core install: 3 passed, 0 failed", out.stdout
    skipped = [line for line in lines if "mpc skipped" in line]
    assert len(skipped) == 1 and "acld-gym[baselines]" in skipped[0], out.stdout
