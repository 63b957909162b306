"""Same results under other CPUs' BLAS kernels: a check to run by hand (issue 15).

OpenBLAS picks its kernels by CPU at run time; ``OPENBLAS_CORETYPE`` forces another
CPU's kernels on this one. This script runs, in a subprocess per kernel (the machine's
default, ``Nehalem``, ``Sandybridge``, and ``Haswell`` where the CPU has AVX2):

* the design (reduced model, observation scales, Kalman gains) of ``ACLDBeam-v1`` on
  both meshes and of ``ACLDBeam-v0``,
* one episode of each (random load, seeded sensor noise, fixed actions),
* the shipped agents' ISE on thesis case 1 (if ``train/agents`` has them),

and prints the largest relative difference of each against the default kernel, and the
sign pattern of the raw Schur coordinates' C_r (``basis="schur"``, which no env observes
since acld-gym 0.3.0; v0 did before), which is what changes between kernels.
It never runs inside the tests or CI: some machines set these variables on purpose.

    python benchmarks/check_kernels.py
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
KERNELS = ["default", "Nehalem", "Sandybridge", "Haswell"]

_CHILD = r"""
import json, sys
import numpy as np
import gymnasium as gym
import acld_gym
from acld_gym.envs.beam_env import ACLDBeamEnv
from acld_gym.design.reduction import schur_balanced_truncation
from acld_gym.physics.truth import plant

out = {}
for label, env_id, kw in (("converged", "ACLDBeam-v1", {}),
                          ("thesis", "ACLDBeam-v1", {"mesh": "thesis"}),
                          ("v0", "ACLDBeam-v0", {})):
    env = gym.make(env_id, load_case="random", **kw).unwrapped
    nom = env.nom
    r = nom.design.reduced
    for name in ("A", "B", "C", "E"):
        out[f"{label}/reduced_{name}"] = getattr(r, name).tolist()
    out[f"{label}/xr_scale"] = nom.xr_scale.tolist()
    out[f"{label}/kalman_Lc"] = nom.kalman.Lc.tolist()
    obs, _ = env.reset(seed=3)
    rows = [obs.tolist()]
    rng = np.random.default_rng(0)
    for _ in range(1000):
        obs, *_ = env.step(rng.uniform(-150, 150, 1).astype(np.float32))
        rows.append(obs.tolist())
    out[f"{label}/episode"] = rows
A, B, E, C = plant("thesis").state_space()
out["raw_schur_sign_C"] = np.sign(schur_balanced_truncation(A, B, C, 6, E=E,
                                                          basis="schur").C).tolist()
try:
    from baselines.evaluate import rollout
    from train.compare import load_agents
    for name, agent in load_agents().items():
        ep = rollout(agent, ACLDBeamEnv(load_case=1), seed=0)
        out[f"agent/{name}/case1_ise"] = float(np.sum(ep.y ** 2) * 1e-3)
except Exception as exc:  # no shipped agents, or they do not load: say so
    out["agent_error"] = repr(exc)
json.dump(out, open(sys.argv[1], "w"))
"""


def _has_avx2() -> bool:
    try:
        return "avx2" in Path("/proc/cpuinfo").read_text()
    except OSError:
        return False


def run(kernel: str, path: Path) -> dict:
    env = dict(os.environ)
    env.pop("OPENBLAS_CORETYPE", None)
    if kernel != "default":
        env["OPENBLAS_CORETYPE"] = kernel
    subprocess.run([sys.executable, "-c", _CHILD, str(path)], env=env, check=True, cwd=ROOT)
    return json.loads(path.read_text())


def main() -> int:
    kernels = [k for k in KERNELS if k != "Haswell" or _has_avx2()]
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        for k in kernels:
            results[k] = run(k, Path(tmp) / f"{k}.json")
            print(f"ran {k}", file=sys.stderr)
    ref = results["default"]
    keys = [k for k in ref if k not in ("raw_schur_sign_C", "agent_error")]
    print(f"{'quantity':32s}" + "".join(f"{k:>14s}" for k in kernels[1:]))
    for key in keys:
        cells = []
        for k in kernels[1:]:
            a, b = np.asarray(results[k].get(key, np.nan)), np.asarray(ref[key])
            rel = float(np.max(np.abs(a - b)) / max(float(np.max(np.abs(b))), 1e-300))
            cells.append(f"{rel:14.1e}")
        print(f"{key:32s}" + "".join(cells))
    print(
        "\nsign(C_r) in the raw Schur coordinates (basis='schur', observed by no env since "
        "0.3.0; by v0 before) -- what changes between kernels:"
    )
    for k in kernels:
        signs = "".join("+" if s > 0 else "-" for s in results[k]["raw_schur_sign_C"][0])
        print(f"  {k:12s} {signs}")
    if "agent_error" in ref:
        print(f"\nagents: {ref['agent_error']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
