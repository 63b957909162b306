"""The documentation's pictures: every image a page shows exists, every file in
docs/figures/ is shown by a page, each has alt text, the animations stay small; the hero
and animation commands of :mod:`train.figures` run on a tiny input."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FIGURES = ROOT / "docs" / "figures"
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
IMAGE = re.compile(r"!\[([^\]]*)\]\(([^)\s]+)\)|<img\s[^>]*src=\"([^\"]+)\"")


def _images() -> list[tuple[Path, str, Path]]:
    """(page, alt text, resolved path) of every local image of every page."""
    out = []
    for page in PAGES:
        for m in IMAGE.finditer(page.read_text(encoding="utf-8")):
            target = m.group(2) or m.group(3)
            if "://" in target:
                continue
            out.append((page, m.group(1) or "", (page.parent / target).resolve()))
    return out


def test_every_image_a_page_shows_exists_and_has_alt_text():
    images = _images()
    assert images, "no image found in the pages: the pattern is wrong"
    missing = [f"{p.relative_to(ROOT)}: {t}" for p, _, t in images if not t.is_file()]
    assert not missing, missing
    no_alt = [f"{p.relative_to(ROOT)}: {t.name}" for p, a, t in images if len(a.split()) < 3]
    assert not no_alt, no_alt


def test_every_file_in_docs_figures_is_shown_by_a_page():
    shown = {t for _, _, t in _images()}
    files = {f.resolve() for f in FIGURES.iterdir() if f.is_file()}
    assert files, "docs/figures/ is empty"
    unused = sorted(f.name for f in files - shown)
    assert not unused, f"in docs/figures/ but on no page: {unused}"


def test_animations_are_small_enough_for_the_repository():
    for f in FIGURES.iterdir():
        if f.suffix in (".gif", ".webp", ".apng"):
            assert f.stat().st_size < 1.5e6, f.name


def test_hero_command_on_a_tiny_input(tmp_path, capsys):
    from PIL import Image

    from train.figures import main

    out = tmp_path / "hero.png"
    args = ["hero", str(out), "--random-episodes", "1", "--episode-length", "0.05"]
    assert main(args) == 0
    with Image.open(out) as im:
        assert im.format == "PNG" and im.size[0] > im.size[1] > 200
    lines = {ln.split(":")[0]: ln for ln in capsys.readouterr().out.splitlines()}
    for case in ("case 1", "case 2", "case 3", "case random"):
        ratios = dict(kv.rsplit(" ", 1) for kv in lines[case].split(": ", 1)[1].split(", "))
        assert ratios["lqr"] == "1.000"
        assert len(ratios) == 5  # the engineer's design: mpc_rig, or lqg without osqp
        assert set(ratios) - {"mpc_rig", "lqg"} == {"passive", "lqr", "ppo", "bound"}
        assert float(ratios["passive"]) > 1.0  # the beam alone is worse than the LQR


def test_hero_refuses_a_bad_path_before_computing(tmp_path, capsys):
    from train.figures import main

    with pytest.raises(SystemExit) as exc:
        main(["hero", str(tmp_path / "hero.gif")])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert "path" in err and ".png" in err
    assert not (tmp_path / "hero.gif").exists()


def test_animation_frames_and_file(tmp_path):
    from PIL import Image

    from acld_gym.envs.beam_env import ACLDBeamEnv
    from baselines.marks import level_references
    from train.figures import beam_frames, save_animation

    policy = level_references(ACLDBeamEnv())["lqr"]
    frames = beam_frames(policy, n_frames=3, stride=2)
    assert len(frames) == 3 and frames[0].ndim == 3 and frames[0].shape[2] == 3
    assert (frames[1] != frames[2]).any()  # the beam moved
    out = save_animation(frames, tmp_path / "beam.gif", fps=5, scale=0.5)
    with Image.open(out) as im:
        assert im.n_frames == 3 and im.info["duration"] == 200
        assert im.size == (round(frames[0].shape[1] / 2), round(frames[0].shape[0] / 2))
    with pytest.raises(ValueError, match="beam.png"):
        save_animation(frames, tmp_path / "beam.png")
    assert not (tmp_path / "beam.png").exists()


def test_sparse_ratio_labels_leave_out_ticks_next_to_one():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from train.figures import sparse_ratio_labels

    fig, ax = plt.subplots()
    ax.set_yscale("log")
    sparse_ratio_labels(ax)
    fmt = ax.yaxis.get_minor_formatter()
    assert [fmt(v, 0) for v in (0.8, 0.9, 2.0, 3.0, 4.0, 5.0, 20.0)] == [
        "0.8",
        "",
        "2",
        "3",
        "",
        "5",
        "20",
    ]
    plt.close(fig)
