"""The guide as a new user meets it (issue 69): getting started opens with the install and
``gym.make``; the settings any RL library should use are stated in one place and every page
and script agrees with it; a time stated in the docs names the machine it was measured on,
and no command's comment carries a bare time; ``train.ship`` sends agents where the user
works; the registry's ``max_episode_steps`` is the made env's episode length."""

from __future__ import annotations

import inspect
import re
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import acld_gym  # noqa: F401  (registers the ids)
from acld_gym.envs.ids import PRESETS
from train import ship

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
#: The pages a user reads as the guide and reference: every page but the history
#: (changelog). The research record is not in docs/ (``studies/studies.md``).
PAGES = sorted(p for p in DOCS.glob("*.md") if p.name != "changelog.md")
#: The pages whose prose timings are checked: the guide's, but for the two whose authors
#: measure them elsewhere (any-library.md states its machine above its table).
TIMED_PAGES = [p for p in PAGES if p.name not in ("any-library.md", "internals.md")]
TIMED_PAGES.append(ROOT / "README.md")
FENCE = re.compile(r"^```[^\n]*\n.*?^```", re.S | re.M)
#: A time: a number and a unit of time (not a unit's power such as m^2 s, not a rate).
TIME = r"(?<![\w.^/-])~?\s?\d[\d.,]*\s?(?:s|sec|seconds?|min|minutes?|h|hours?)\b(?!\s*/)"
DURATION = re.compile(TIME)
#: A time stated as how long something runs ("takes 38 s", "2 min per seed", "~1 min").
RUN_TIME = re.compile(
    rf"\b(?:takes?|took|runs? in|in about)\s(?:[^.;:()\n]{{0,30}}?\s)?{TIME}"
    rf"|{TIME}\s(?:of (?:wall|CPU|training)|per (?:seed|run|trial))"
    r"|~\s?\d[\d.,]*\s?(?:s|min|h)\b|\ba minute\b",
    re.I,
)
MACHINE = re.compile(r"\b(?:cores?|container|machine|CPUs?|EPYC|Xeon)\b")


def section(text: str, heading: str) -> str:
    """The body of the ``## heading`` section of a page."""
    match = re.search(rf"^## {re.escape(heading)}\n(.*?)(?=^## |\Z)", text, re.S | re.M)
    assert match, f"no section '## {heading}'"
    return match[1]


def comments(text: str) -> list[str]:
    """The comments (after ``#``) of a page's code blocks, shell and Python."""
    out = []
    for block in FENCE.findall(text):
        for line in block.splitlines()[1:-1]:
            code, sep, comment = line.partition("#")
            if sep and not code.rstrip().endswith(("'", '"')):
                out.append(comment)
    return out


def test_getting_started_opens_with_the_install_then_make_reset_step():
    text = (DOCS / "getting-started.md").read_text()
    assert re.findall(r"^## (.+)$", text, re.M)[:3] == [
        "Install",
        "Make, reset, step",
        "Two commands",
    ]
    install = section(text, "Install")
    for line in ("git clone", "pip install -e .", 'pip install -e ".[baselines,train]"'):
        assert line in install, line
    assert "acld-gym --version" in install
    assert '--8<-- "README.md:quickstart"' in section(text, "Make, reset, step")
    readme = (ROOT / "README.md").read_text()
    quick = readme.split("[start:quickstart]", 1)[1].split("[end:quickstart]", 1)[0]
    first = FENCE.search(quick)[0]
    assert first.startswith("```python\nimport gymnasium as gym")
    assert first.index("gym.make(") < first.index(".reset(") < first.index(".step(")


@pytest.mark.parametrize("page", [*PAGES, ROOT / "README.md"], ids=lambda p: p.name)
def test_no_bare_time_in_a_commands_comment(page):
    """A time after a command ('# ~1 min') cannot say on what machine it was measured: it
    goes in the prose or a table, with the machine and the command, or not at all."""
    bare = [c.strip() for c in comments(page.read_text()) if DURATION.search(c)]
    assert not bare, bare


@pytest.mark.parametrize("page", TIMED_PAGES, ids=lambda p: p.name)
def test_a_stated_time_names_its_machine(page):
    text = FENCE.sub("", re.sub(r"<!--.*?-->", "", page.read_text(), flags=re.S))
    bare = [
        " ".join(para.split())[:160]
        for para in re.split(r"\n\s*\n", text)
        if RUN_TIME.search(para) and not MACHINE.search(para)
    ]
    assert not bare, bare


def test_the_probes_catch_what_they_should():
    assert comments("```bash\npython -m x   # from scratch, ~1 min\n```\n") == [
        " from scratch, ~1 min"
    ]
    assert DURATION.search(" from scratch, ~1 min") and DURATION.search("took 6:06 or 366 s")
    assert not DURATION.search("[m^2 s, mm, s]") and not DURATION.search("3,300 steps/s")
    assert not DURATION.search("1e-3 s/step") and not DURATION.search("ACLDBeam-v1s")
    assert RUN_TIME.search("make run takes about a minute") and not MACHINE.search("a minute")
    assert RUN_TIME.search("the command takes 38.6 s") and RUN_TIME.search("2.1 min per seed")
    assert not RUN_TIME.search("the voltage switches until about 0.3 s")
    assert not RUN_TIME.search("settles at 0.34 s; 2 s of tip response")


def test_the_settings_for_any_library_are_stated_once_and_agreed_on():
    one_place = section(
        (DOCS / "training.md").read_text(), "Any library: the Gymnasium env, and what to add"
    )
    for name in (
        "acld_gym.wrappers.UnitAction",
        "headroom=3.0",
        'reward_scale="passive"',
        "ObserveModes(env,\n   modes=1)",
        "VecNormalize",
        "NormalizeObservation",
        "torch.set_num_threads(1)",
        "RescaleAction",  # named once, with why the pages use UnitAction instead
    ):
        assert name in one_place, name
    readme = (ROOT / "README.md").read_text()
    any_library = (DOCS / "any-library.md").read_text()
    for text in (readme, any_library):
        for name in ("UnitAction", 'reward_scale="passive"', "ObserveModes", "headroom=3.0"):
            assert name in text, name
    for script in ("sb3_ppo.py", "sb3_sac.py"):
        code = (DOCS / "examples" / script).read_text()
        for name in ("UnitAction", 'reward_scale="passive"', "ObserveModes", "VecNormalize"):
            assert name in code, (script, name)
        assert "torch.set_num_threads(1)" in code, script
    # no page recommends another action scaling, and no page's code trains through one
    advice = re.compile(
        r"(?:train|use|wrap)\w*\s+(?:it\s+)?with\s+`*(?:gymnasium\.wrappers\.)?RescaleAction"
    )
    for page in [*PAGES, ROOT / "README.md"]:
        text = page.read_text()
        assert not advice.search(text), page.name
        for block in FENCE.findall(text):
            assert "RescaleAction(" not in block, page.name


def test_shipped_agents_go_where_the_user_works():
    for page in [*PAGES, ROOT / "README.md"]:
        for line in page.read_text().splitlines():
            if "train.ship" in line and "->" in line:
                assert "train/agents" not in line.split("->", 1)[1], (page.name, line)
    # the default is a relative folder: the current directory's, never the package's
    assert not Path(ship.DEFAULT_AGENTS).is_absolute()
    assert inspect.signature(ship.ship).parameters["agents_dir"].default == ship.DEFAULT_AGENTS
    assert Path(ship.DEFAULT_AGENTS).parts[:1] != ("train",)


@pytest.mark.parametrize("env_id", list(PRESETS))
def test_the_registry_reports_the_made_envs_episode_length(env_id):
    """A tool that reads ``gym.spec(id).max_episode_steps`` plans for as many steps as an
    episode of the made env has: stepped until it ends, it truncates exactly there."""
    env = gym.make(env_id)
    env.reset(seed=0)
    steps, done = 0, False
    while not done:
        _, _, terminated, truncated, _ = env.step(np.zeros(1, dtype=np.float32))
        steps += 1
        assert not terminated and steps <= 10_000
        done = truncated
    assert steps == gym.spec(env_id).max_episode_steps == env.spec.max_episode_steps
    env.close()


def test_the_home_page_says_whom_it_is_for_before_the_figure():
    home = (DOCS / "index.md").read_text()
    first_screen = home[: home.index("![")]
    for words in ("question it answers", "RL researchers", "control researchers"):
        assert words in first_screen, words
    guide = home[home.index("**Guide**") :]
    for page in ("getting-started.md", "any-library.md", "training.md", "leaderboard.md"):
        assert f"]({page})" in guide, page


@pytest.mark.parametrize("page", [*PAGES, ROOT / "README.md"], ids=lambda p: p.name)
def test_every_sb3_model_a_page_builds_is_on_one_torch_thread(page):
    """A plain SB3 script on torch's default threads ran 15-25x slower on 2 cores: every
    page's code that builds an SB3 model sets one thread before it."""
    code = ""
    for block in re.findall(r"^```python\n(.*?)^```", page.read_text(), flags=re.S | re.M):
        code += block
        for model in re.finditer(r"\b(?:PPO|SAC|TD3|A2C|DDPG|TQC|CrossQ)\(", block):
            before = code[: len(code) - len(block) + model.start()]
            assert "torch.set_num_threads(1)" in before, (page.name, block[:80])
