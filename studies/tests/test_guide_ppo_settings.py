"""``studies/probes/guide_ppo_settings.py``: the guide's SB3 PPO script with some of its
settings as arguments and nothing else changed (at the script's own values the probe is the
script)."""

from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _body(path: Path) -> list[str]:
    text = path.read_text()
    return text[text.index('"""', 3) + 3 :].splitlines()  # after the module docstring


def test_the_probe_is_the_script_at_its_defaults():
    probe = _body(ROOT / "studies/probes/guide_ppo_settings.py")
    added = [
        "import json",
        'p.add_argument("--ent", type=float, default=0.05)',
        'p.add_argument("--gamma", type=float, default=0.999)',
        'p.add_argument("--pi", type=json.loads, default=[])',
        'p.add_argument("--sde", action=argparse.BooleanOptionalAction, default=True)',
        'p.add_argument("--epochs", type=int, default=5)',
        'p.add_argument("--batch", type=int, default=512)',
    ]
    assert all(line in probe for line in added)
    defaults = {"gamma": "0.999", "ent": "0.05", "pi": "[]", "sde": "True", "epochs": "5"}
    defaults["batch"] = "512"
    at_defaults = []
    for line in probe:
        if line in added:
            continue
        line = line.removesuffix("  # noqa: E501")  # the one line the arguments lengthen
        for name, value in defaults.items():
            line = line.replace(f"args.{name}", value)
        at_defaults.append(line)
    assert at_defaults == _body(ROOT / "docs/examples/sb3_ppo.py")


def test_the_sac_probe_is_the_script_at_its_defaults():
    probe = _body(ROOT / "studies/probes/guide_sac_settings.py")
    ent = 'type=lambda s: s if s.startswith("auto") else float(s), default="auto"'
    added = f'p.add_argument("--ent", {ent})'
    assert added in probe
    at_defaults = [
        line.replace(" ent_coef=args.ent,", "").removesuffix("  # noqa: E501")
        for line in probe
        if line != added
    ]
    assert at_defaults == _body(ROOT / "docs/examples/sb3_sac.py")
