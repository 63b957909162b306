"""Fuzz of the agent files (issue 65, deliverable 5): an agent's ``metadata.json`` and
``policy.npz``, mutated by deletion, type change and truncation (and, for the archive,
added members and flipped bytes), either load into a working policy or are refused with
:class:`train.agent.AgentFileError`; no other exception, ever.

A load that succeeds is checked for a correct result: the observation fingerprint matched
the env's (``check=True``), and the policy maps observations of the env's width to finite
voltages within +/-120 V.
"""

from __future__ import annotations

import copy
import io
import json
import tempfile
import warnings
import zipfile
from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from train.agent import CURVE_FILE, META_FILE, POLICY_FILE, AgentFileError, TrainedAgent
from train.agent_files import curve_rows, read_curve
from train.compare import AGENTS_DIR
from train.ship import ship

ROOT = Path(__file__).resolve().parents[2]
#: Agents with every operation the shipped ones use: linear; linear, clip, tanh; direction.
SOURCES = [AGENTS_DIR / "ppo", AGENTS_DIR / "sac", ROOT / "tests/data/agents/ppo_dagger"]
#: What a value may become: every JSON type, edge numbers, a hostile id, an operation.
VALUES = [
    None,
    True,
    0,
    -1,
    2.5,
    1e308,
    -1e308,
    10**400,
    "",
    "x",
    "ACLDBeam-v1",
    "evil_agent:ACLDBeam-v1",
    [],
    [1, "a"],
    [[1.0], [2.0, 3.0]],
    {},
    {"op": "clip"},
    {"a": 1},
]
#: Keys an insertion adds: env settings, operation parameters, top-level fields, junk.
KEYS = ["mesh", "dt", "sensor_noise", "temperature", "obs_mode", "layer", "low", "high"]
KEYS += ["clip", "eps", "id", "kwargs", "format", "residual", "action_headroom", "junk"]
FUZZ = settings(
    max_examples=300,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
    derandomize=True,
)


def _paths(obj, prefix=()):
    """Every path (keys and indices) to a node of JSON data, the root excluded."""
    items = (
        obj.items() if isinstance(obj, dict) else enumerate(obj) if isinstance(obj, list) else ()
    )
    for key, value in items:
        yield (*prefix, key)
        yield from _paths(value, (*prefix, key))


def _node(meta, path):
    for key in path:
        meta = meta[key]
    return meta


def _mutate(meta, path, action, value):
    """``meta`` with the node at ``path`` deleted (``action`` "delete") or set to
    ``value`` (added, for a new key)."""
    *parents, last = path
    node = meta
    for key in parents:
        node = node[key]
    if action == "delete":
        del node[last]
    else:
        node[last] = copy.deepcopy(value)
    return meta


def _loads_or_refuses(directory: Path) -> None:
    """The property: AgentFileError, or an agent whose voltages are finite and in range."""
    try:
        agent = TrainedAgent.load(directory)
    except AgentFileError:
        return
    width = agent.actor.arrays[f"W{_first_layer(agent)}"].shape[0]
    if agent.actor.ops[0]["op"] == "direction":
        width -= 1
    obs = np.random.default_rng(0).normal(size=(6, width)).astype(np.float32)
    volts, _ = agent.predict(obs)
    assert volts.shape == (6, 1)
    assert np.all(np.isfinite(volts)) and np.all(np.abs(volts) <= 120.0)


def _first_layer(agent) -> int:
    return next(op["layer"] for op in agent.actor.ops if op["op"] == "linear")


def _write(d: Path, source: Path, meta_text: str | None = None, policy: bytes | None = None):
    d.mkdir()
    (d / META_FILE).write_text(
        meta_text if meta_text is not None else (source / META_FILE).read_text()
    )
    (d / POLICY_FILE).write_bytes(
        policy if policy is not None else (source / POLICY_FILE).read_bytes()
    )


@st.composite
def metadata_texts(draw):
    source = draw(st.sampled_from(SOURCES))
    meta = json.loads((source / META_FILE).read_text())
    for _ in range(draw(st.integers(1, 3))):
        paths = list(_paths(meta))
        if not paths:
            break
        action = draw(st.sampled_from(["delete", "retype", "insert"]))
        value = draw(st.sampled_from(VALUES))
        if action == "insert":  # a new key in an object: the root, env.kwargs, an op, ...
            objects = [()] + [p for p in paths if isinstance(_node(meta, p), dict)]
            path = (*draw(st.sampled_from(objects)), draw(st.sampled_from(KEYS)))
        else:
            path = draw(st.sampled_from(paths))
        meta = _mutate(meta, path, action, value)
    text = json.dumps(meta)
    if draw(st.booleans()):
        text = text[: draw(st.integers(0, len(text)))]
    return source, text


@given(metadata_texts())
@FUZZ
def test_mutated_metadata_loads_or_is_an_agent_file_error(case):
    source, text = case
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp) / "agent"
        _write(d, source, meta_text=text)
        _loads_or_refuses(d)


#: What an array may become: other dtypes (text, bytes, complex, bool, int, object),
#: dimensions (0, 3), an empty one, huge or non-finite values.
ARRAYS = [
    np.array(["0.5", "1.5"]),
    np.array([b"abc"]),
    np.ones(3, dtype=complex),
    np.ones(9, dtype=bool),
    np.arange(9),
    np.array([{"a": 1}], dtype=object),
    np.float64(1.0),
    np.ones((9, 1, 1)),
    np.zeros(0),
    np.full((9, 1), 1e300),
    np.array([np.nan]),
]


def _archive(members: dict[str, object]) -> bytes:
    """A zip of ``.npy`` members (bytes as given, arrays serialized as np.save does)."""
    buf = io.BytesIO()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # duplicate names, on purpose
        with zipfile.ZipFile(buf, "w") as z:
            for name, value in members.items():
                if isinstance(value, bytes):
                    z.writestr(name.split("#")[0], value)
                else:
                    arr = io.BytesIO()
                    np.lib.format.write_array(arr, np.asanyarray(value), allow_pickle=True)
                    z.writestr(name.split("#")[0], arr.getvalue())
    return buf.getvalue()


@st.composite
def policy_archives(draw):
    source = draw(st.sampled_from(SOURCES))
    with np.load(source / POLICY_FILE) as z:
        members: dict[str, object] = {f"{k}.npy": z[k] for k in z.files}
    kind = draw(st.sampled_from(["delete", "retype", "add", "truncate", "flip"]))
    names = sorted(members)
    if kind == "delete":
        del members[draw(st.sampled_from(names))]
    elif kind == "retype":
        members[draw(st.sampled_from(names))] = draw(st.sampled_from(ARRAYS))
    elif kind == "add":
        name = draw(st.sampled_from(["x.npy", "W1.npy", "mean.npy", "a/../W0.npy", "W0.npy#2"]))
        members[name] = draw(st.sampled_from([*ARRAYS, b"not an array"]))
    data = _archive(members)
    if kind == "truncate":
        data = data[: draw(st.integers(0, len(data) - 1))]
    elif kind == "flip":
        at = draw(st.integers(0, len(data) - 1))
        data = data[:at] + bytes([data[at] ^ draw(st.integers(1, 255))]) + data[at + 1 :]
    return source, data


@given(policy_archives())
@FUZZ
def test_mutated_archive_loads_or_is_an_agent_file_error(case):
    source, data = case
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp) / "agent"
        _write(d, source, policy=data)
        _loads_or_refuses(d)


def test_the_fuzz_reaches_both_outcomes():
    """The mutations are neither all refused nor all harmless: a deleted informational
    field or integer weights load; a deleted env id or operation, text weights are refused."""
    source = SOURCES[0]
    meta = json.loads((source / META_FILE).read_text())
    with np.load(source / POLICY_FILE) as z:
        members = {f"{k}.npy": z[k] for k in z.files}
    cases = [
        ({"meta": ("seed",)}, True),
        ({"meta": ("env", "id")}, False),
        ({"meta": ("actor", 0, "op")}, False),
        ({"b0.npy": np.arange(1)}, True),
        ({"b0.npy": ARRAYS[0]}, False),
    ]
    with tempfile.TemporaryDirectory() as tmp:
        for i, (change, loads) in enumerate(cases):
            d = Path(tmp) / str(i)
            if "meta" in change:
                text = json.dumps(_mutate(copy.deepcopy(meta), change["meta"], "delete", None))
                _write(d, source, meta_text=text)
            else:
                _write(d, source, policy=_archive({**members, **change}))
            assert _loads(d) is loads, change


def _loads(d: Path) -> bool:
    try:
        TrainedAgent.load(d)
    except AgentFileError:
        return False
    return True


@st.composite
def curve_texts(draw):
    """A shipped learning curve with a line deleted, a field retyped, or cut short."""
    lines = (SOURCES[0] / CURVE_FILE).read_text().splitlines()
    i = draw(st.integers(0, len(lines) - 1))
    kind = draw(st.sampled_from(["delete", "retype", "truncate"]))
    if kind == "delete":
        del lines[i]
    elif kind == "retype":
        fields = lines[i].split(",")
        j = draw(st.integers(0, len(fields) - 1))
        fields[j] = draw(st.sampled_from(["", "x", "-1", "nan", "inf", "1e999", "0", "1,2"]))
        lines[i] = ",".join(fields)
    text = "\n".join(lines) + "\n"
    if kind == "truncate":
        text = text[: draw(st.integers(0, len(text)))]
    return text


@given(curve_texts())
@settings(FUZZ, max_examples=60)  # each example ships (fsyncs) and loads three times
def test_a_mutated_learning_curve_ships_whole_or_is_an_agent_file_error(text):
    """Shipping copies a curve whose every row reads, byte for byte, with the agent (which
    then loads as it was); any other curve is an AgentFileError and nothing is written."""
    with tempfile.TemporaryDirectory() as tmp:
        run, agents = Path(tmp) / "run", Path(tmp) / "agents"
        _write(run, SOURCES[0])
        (run / CURVE_FILE).write_text(text)
        try:
            dst = ship(run, "mine", agents)
        except AgentFileError:
            assert not agents.exists()
            return
        assert (dst / CURVE_FILE).read_text() == text
        assert curve_rows(text, "x") == read_curve(dst)
        shipped, original = TrainedAgent.load(dst), TrainedAgent.load(run)
        assert shipped.actor.ops == original.actor.ops
        for key, value in original.actor.arrays.items():
            assert np.array_equal(shipped.actor.arrays[key], value)
