"""``studies/probes/guide_ppo_entropy.py``: the guide's SB3 PPO script with its entropy
coefficient and discount as arguments and nothing else changed (at the script's own values
the probe is the script)."""

from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _body(path: Path) -> list[str]:
    text = path.read_text()
    return text[text.index('"""', 3) + 3 :].splitlines()  # after the module docstring


def test_the_probe_is_the_script_at_its_defaults():
    probe = _body(ROOT / "studies/probes/guide_ppo_entropy.py")
    added = [
        'p.add_argument("--ent", type=float, default=0.05)',
        'p.add_argument("--gamma", type=float, default=0.999)',
    ]
    assert all(line in probe for line in added)
    at_defaults = [
        line.replace("args.gamma", "0.999").replace("args.ent", "0.05")
        for line in probe
        if line not in added
    ]
    assert at_defaults == _body(ROOT / "docs/examples/sb3_ppo.py")
