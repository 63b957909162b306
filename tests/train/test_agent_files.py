"""An agent folder is data (issue 65): loading never imports or executes anything from it,
never follows a link into or out of it, checks the archive before decompressing it and
names the file and field of every fault; shipping writes the folder whole, or leaves the
old one, and needs ``--force`` to replace one."""

from __future__ import annotations

import io
import json
import os
import shutil
import subprocess
import sys
import time
import tracemalloc
import zipfile
from pathlib import Path

import numpy as np
import pytest

from train.agent import CURVE_FILE, META_FILE, POLICY_FILE, AgentFileError, TrainedAgent
from train.agent_files import check_replaceable, curve_rows, read_metadata
from train.compare import AGENTS_DIR
from train.ship import main as ship_main
from train.ship import ship

ROOT = Path(__file__).resolve().parents[2]


def _copy(name: str, dst: Path) -> Path:
    shutil.copytree(AGENTS_DIR / name, dst)
    return dst


def _meta(d: Path) -> dict:
    return json.loads((d / META_FILE).read_text())


def _set_meta(d: Path, meta) -> None:
    (d / META_FILE).write_text(meta if isinstance(meta, str) else json.dumps(meta))


def _evil(tmp_path: Path) -> tuple[Path, Path]:
    """An agent folder that is also a Python package whose import writes a marker, and
    whose env id asks Gymnasium to import it (``"evil_agent:ACLDBeam-v1"``)."""
    d = _copy("vrs", tmp_path / "evil_agent")
    marker = tmp_path / "imported"
    (d / "__init__.py").write_text(f"open({str(marker)!r}, 'w').close()\n")
    meta = _meta(d)
    meta["env"]["id"] = meta["observation"]["env_id"] = "evil_agent:ACLDBeam-v1"
    _set_meta(d, meta)
    return d, marker


# --- nothing runs from an agent folder -----------------------------------------------------
def test_a_module_env_id_imports_nothing(tmp_path, monkeypatch):
    d, marker = _evil(tmp_path)
    monkeypatch.syspath_prepend(str(tmp_path))
    for check in (True, False):
        with pytest.raises(AgentFileError, match=rf"{META_FILE}: env.id must be one of"):
            TrainedAgent.load(d, check=check)
    assert not marker.exists() and "evil_agent" not in sys.modules


@pytest.mark.parametrize(
    "command",
    [
        ["train.analyze", "evil_agent", "--quiet"],
        ["train.compare", "--agents", ".", "--only", "evil_agent", "--quiet"],
    ],
)
def test_the_commands_run_nothing_from_the_agents_parent_folder(tmp_path, command):
    """The probe's case: ``python -m train.analyze evil_agent`` (or ``train.compare``)
    run from the folder holding it (so that the agent is importable) exits with one line
    and runs nothing."""
    _, marker = _evil(tmp_path)
    env = dict(os.environ, PYTHONPATH=str(ROOT), OMP_NUM_THREADS="1")
    run = subprocess.run(
        [sys.executable, "-m", *command],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert run.returncode == 2, run.stderr
    assert not marker.exists()
    assert "Traceback" not in run.stderr
    assert "env.id must be one of this package's ids" in run.stderr.splitlines()[-1]


# --- no link followed, only regular files, size limits --------------------------------------
@pytest.mark.parametrize("name", [POLICY_FILE, META_FILE])
def test_a_symlinked_file_is_refused(tmp_path, name):
    """A ``policy.npz`` linked to another agent's would run under this agent's metadata."""
    d = _copy("vrs", tmp_path / "a")
    other = _copy("sac", tmp_path / "b")
    (d / name).unlink()
    (d / name).symlink_to(other / name)
    with pytest.raises(AgentFileError, match=rf"{name}: is a symbolic link"):
        TrainedAgent.load(d, check=False)


def test_a_symlinked_folder_a_fifo_and_a_directory_are_refused(tmp_path):
    d = _copy("vrs", tmp_path / "a")
    (tmp_path / "link").symlink_to(d)
    with pytest.raises(AgentFileError, match="link: is a symbolic link"):
        TrainedAgent.load(tmp_path / "link", check=False)
    (d / POLICY_FILE).unlink()
    os.mkfifo(d / POLICY_FILE)  # reading it would block forever
    with pytest.raises(AgentFileError, match=rf"{POLICY_FILE}: is not a regular file"):
        TrainedAgent.load(d, check=False)
    (d / POLICY_FILE).unlink()
    (d / POLICY_FILE).mkdir()
    with pytest.raises(AgentFileError, match=rf"{POLICY_FILE}: is not a regular file"):
        TrainedAgent.load(d, check=False)
    with pytest.raises(FileNotFoundError, match="does not exist"):
        TrainedAgent.load(tmp_path / "nothing")
    with pytest.raises(NotADirectoryError, match="not a directory"):
        TrainedAgent.load(d / META_FILE)


def test_an_oversized_metadata_file_is_refused_unread(tmp_path):
    d = _copy("vrs", tmp_path / "a")
    with open(d / META_FILE, "r+b") as fh:
        fh.truncate(2 << 20)  # 2 MiB, sparse
    with pytest.raises(AgentFileError, match=rf"{META_FILE}: 2097152 bytes, more than"):
        TrainedAgent.load(d, check=False)


# --- the archive: checked by name, declared size and header before decompression ----------
def _arrays(d: Path) -> dict:
    with np.load(d / POLICY_FILE) as z:
        return {k: z[k] for k in z.files}


def test_an_unused_400_mb_member_is_refused_without_decompressing_it(tmp_path):
    """The probe's archive: a small file declaring a 400 MB array the actor does not use.
    Refused by its name, in well under a second and without allocating it."""
    d = _copy("vrs", tmp_path / "a")
    with zipfile.ZipFile(d / POLICY_FILE, "a", zipfile.ZIP_DEFLATED) as z:
        with z.open("junk.npy", "w", force_zip64=True) as fh:
            header = np.lib.format.header_data_from_array_1_0(np.zeros(1))
            header["shape"] = (50_000_000,)
            np.lib.format.write_array_header_1_0(fh, header)
            block = bytes(1 << 22)
            for _ in range(400_000_000 // len(block)):
                fh.write(block)
    assert (d / POLICY_FILE).stat().st_size < 1_000_000
    tracemalloc.start()
    t0 = time.perf_counter()
    with pytest.raises(AgentFileError, match=r"members \['junk.npy'\] are not arrays the actor"):
        TrainedAgent.load(d, check=False)
    seconds = time.perf_counter() - t0
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert seconds < 1.0 and peak < 20e6


def test_a_used_member_over_the_size_limit_is_refused_before_decompression(tmp_path):
    d = _copy("vrs", tmp_path / "a")
    arrays = _arrays(d)
    n = 9_000_000  # W0 as 9 x 1e6: 72 MB declared, more than MAX_POLICY_BYTES
    arrays["W0"] = np.zeros((9, n // 9))
    np.savez_compressed(d / POLICY_FILE, **arrays)
    with pytest.raises(AgentFileError, match=r"its arrays declare \d+ bytes, more than"):
        TrainedAgent.load(d, check=False)


@pytest.mark.parametrize(
    "value, match",
    [
        (np.array(["0.5", "1.5"]), "holds '<U3' values, expected real numbers"),
        (np.array([b"abc", b"def"]), "holds '|S3' values, expected real numbers"),
        (np.ones((1, 1, 8)), r"has shape \(1, 1, 8\), expected a vector or a matrix"),
        (np.ones(8, dtype=complex), "holds '<c16' values, expected real numbers"),
    ],
)
def test_a_member_that_is_not_a_real_array_is_named_without_its_bytes(tmp_path, value, match):
    d = _copy("vrs", tmp_path / "a")
    arrays = _arrays(d)
    arrays["b0"] = value
    np.savez(d / POLICY_FILE, **arrays)
    with pytest.raises(AgentFileError, match=rf"{POLICY_FILE}: array 'b0' {match}") as err:
        TrainedAgent.load(d, check=False)
    assert "0.5" not in str(err.value) and "abc" not in str(err.value)


def test_missing_extra_and_damaged_members_are_named(tmp_path):
    d = _copy("vrs", tmp_path / "a")
    arrays = _arrays(d)
    np.savez(d / POLICY_FILE, W0=arrays["W0"])
    with pytest.raises(AgentFileError, match=rf"{POLICY_FILE}: missing array 'b0'"):
        TrainedAgent.load(d, check=False)
    np.savez(d / POLICY_FILE, **arrays, W1=arrays["W0"])
    with pytest.raises(AgentFileError, match=r"members \['W1.npy'\] are not arrays"):
        TrainedAgent.load(d, check=False)
    np.savez(d / POLICY_FILE, **arrays)
    data = bytearray((d / POLICY_FILE).read_bytes())
    data[data.index(b"W0.npy") + 6 + 140] ^= 0xFF  # a byte of W0's data: its CRC fails
    (d / POLICY_FILE).write_bytes(bytes(data))
    with pytest.raises(AgentFileError, match=rf"{POLICY_FILE}: array 'W0' is damaged"):
        TrainedAgent.load(d, check=False)


def test_an_archive_needing_an_unknown_zip_version_is_named(tmp_path):
    """Found by the fuzz: zipfile raises NotImplementedError for a member whose central
    record asks for zip version 8.4."""
    d = _copy("vrs", tmp_path / "a")
    data = bytearray((d / POLICY_FILE).read_bytes())
    record = data.rindex(b"PK\x01\x02")
    data[record + 6] = 84  # "version needed to extract"
    (d / POLICY_FILE).write_bytes(bytes(data))
    with pytest.raises(AgentFileError, match=rf"{POLICY_FILE}: not a readable numpy archive"):
        TrainedAgent.load(d, check=False)


def _npy(header: bytes) -> bytes:
    """A .npy member of format 1.0 with this header dict and 8 bytes of data."""
    pad = b" " * ((64 - (len(header) + 11) % 64) % 64) + b"\n"
    return b"\x93NUMPY\x01\x00" + (len(header) + len(pad)).to_bytes(2, "little") + header + pad


@pytest.mark.parametrize(
    "shape, descr, match",
    [
        (b"(-1,)", b"'<f8'", r"has shape \(-1,\), expected a vector"),
        (b"(" * 3000 + b")" * 3000, b"'<f8'", "is damaged"),
        (b"(1,)", b"__import__('os').system('touch PWNED')", "is damaged"),
        (b"(1,)", b"[('a', '<f8')]", "holds '|V8' values"),
    ],
)
def test_a_hostile_npy_header_is_refused_without_evaluating_it(tmp_path, shape, descr, match):
    d = _copy("vrs", tmp_path / "a")
    header = b"{'descr': " + descr + b", 'fortran_order': False, 'shape': " + shape + b", }"
    arrays = _arrays(d)
    with zipfile.ZipFile(d / POLICY_FILE, "w") as z:
        z.writestr("W0.npy", _npy(header) + bytes(8))
        buf = io.BytesIO()
        np.save(buf, arrays["b0"])
        z.writestr("b0.npy", buf.getvalue())
    with pytest.raises(AgentFileError, match=rf"{POLICY_FILE}: array 'W0' {match}"):
        TrainedAgent.load(d, check=False)
    assert not (tmp_path / "PWNED").exists() and not Path("PWNED").exists()


def test_an_archive_listing_thousands_of_members_is_refused(tmp_path):
    d = _copy("vrs", tmp_path / "a")
    with zipfile.ZipFile(d / POLICY_FILE, "a") as z:
        for i in range(5000):
            z.writestr(f"m{i}", b"")
    with pytest.raises(AgentFileError, match=rf"{POLICY_FILE}: more than 256 members"):
        TrainedAgent.load(d, check=False)


# --- malformed metadata: one error naming the file and the field ----------------------------
def _deep(n: int) -> str:
    return '{"actor": ' + "[" * n + "]" * n + "}"


MALFORMED = [
    (lambda m: {**m, "env": "ACLDBeam-v1"}, "env: expected an object"),
    (lambda m: {**m, "env": {"kwargs": {}}}, "env.id: missing"),
    (lambda m: {**m, "env": {"id": "ACLDBeam-v1", "kwargs": []}}, "env.kwargs: expected an"),
    (lambda m: {**m, "env": {"id": "ACLDBeam-v9"}}, "env.id must be one of"),
    (lambda m: {**m, "env": {"id": "CartPole-v1"}}, "env.id must be one of"),
    (lambda m: {**m, "env": {"id": ["ACLDBeam-v1"]}}, "env.id: expected one of this"),
    (lambda m: {**m, "env": {"id": "x" * 10**5}}, r"env.id: expected one of .*x\.\.\.$"),
    (
        lambda m: {**m, "env": {"id": "ACLDBeam-v1", "kwargs": {"dt": 10**400}}},
        r"env: dt must be a finite real number s, got 10+\.\.\.$",
    ),
    (
        lambda m: {**m, "env": {"id": "ACLDBeam-v1", "kwargs": {"mesh": ["x"]}}},
        "env: mesh must be one of",
    ),
    (
        lambda m: {**m, "env": {"id": "ACLDBeam-v1", "kwargs": {"max_episode_steps": 5}}},
        r"env.kwargs: \['max_episode_steps'\] are not env settings",
    ),
    (lambda m: {**m, "actor": {"op": "linear"}}, "actor: expected a list of operations"),
    (lambda m: {**m, "actor": [{"op": "linear"}, {"op": "clip"}]}, r"actor\[1\]: 'clip' needs"),
    (
        lambda m: {**m, "actor": [{"op": "linear"}, {"op": "clip", "low": 1, "high": -1}]},
        r"actor\[1\]: clip needs low <= high",
    ),
    (lambda m: {**m, "actor": [{"op": "exec"}]}, r"actor\[0\]: unknown operation 'exec'"),
    (lambda m: {**m, "actor": [{"op": "tanh"}]}, "actor: no linear layer"),
    (lambda m: {**m, "actor": [{"op": "linear", "layer": "0"}]}, r"actor\[0\].layer: expected"),
    (lambda m: {**m, "observation": []}, "observation: expected an object"),
    (
        lambda m: {**m, "observation": {**m["observation"], "xr_scale": ["a"]}},
        "observation.xr_scale: expected a list of numbers",
    ),
    (
        lambda m: {k: v for k, v in m.items() if k != "observation"},
        r"lacks \['observation'\]",
    ),
    (lambda m: {**m, "format": 99}, "format: expected an agent format 1 to 3"),
    (lambda m: {**m, "residual": "mpc"}, "residual: expected null or 'lqr'"),
    (lambda m: {**m, "algo": ["x"]}, "algo: expected null or one printable line"),
    (lambda m: {**m, "training": "ok\x1b[2J"}, "training: expected null or one printable"),
    (lambda m: json.dumps(m).replace('"seed": 0', '"seed": NaN'), "not valid JSON"),
    (lambda m: json.dumps(m).replace('"seed": 0', '"seed": ' + "9" * 5000), "not valid JSON"),
    (lambda m: {**m, "action_headroom": 10**400}, "action_headroom: expected a number"),
    (lambda m: _deep(200_000), "nested deeper than 32 levels"),
    (lambda m: _deep(40), "nested deeper than 32 levels"),
    (lambda m: "\xff\xfe", "not valid JSON"),
    (lambda m: [m], "expected a JSON object, got list"),
]


@pytest.mark.parametrize("change, match", MALFORMED)
def test_malformed_metadata_is_one_error_naming_file_and_field(tmp_path, change, match):
    d = _copy("vrs", tmp_path / "a")
    meta = _meta(d)
    assert meta["seed"] == 0
    _set_meta(d, change(meta))
    with pytest.raises(AgentFileError, match=rf"{META_FILE}: .*{match}"):
        TrainedAgent.load(d)


# --- shipping: whole or not at all, --force to replace -------------------------------------
def test_ship_refuses_an_existing_name_without_force(tmp_path, capsys):
    agents = tmp_path / "agents"
    _copy("vrs", agents / "mine")
    before = (agents / "mine" / POLICY_FILE).read_bytes()
    run = _copy("sac", tmp_path / "run")
    with pytest.raises(SystemExit) as exit_:
        ship_main([str(run), "mine", "--agents", str(agents)])
    assert exit_.value.code == 2
    assert "pass --force to replace it" in capsys.readouterr().err.splitlines()[-1]
    assert (agents / "mine" / POLICY_FILE).read_bytes() == before
    (agents / "mine" / "model.zip").write_bytes(b"stale pickle")
    assert ship_main([str(run), "mine", "--agents", str(agents), "--force"]) == 0
    assert (agents / "mine" / POLICY_FILE).read_bytes() == (run / POLICY_FILE).read_bytes()
    assert not (agents / "mine" / "model.zip").exists()  # the folder was replaced whole
    assert TrainedAgent.load(agents / "mine").metadata["algo"] == "sac"
    assert [p.name for p in agents.iterdir()] == ["mine"]  # no temporary left


@pytest.mark.parametrize("agents, match", [("/dev/null", "exists and is not a directory")])
def test_ship_names_an_unusable_agents_folder(tmp_path, capsys, agents, match):
    with pytest.raises(SystemExit) as exit_:
        ship_main([str(AGENTS_DIR / "vrs"), "mine", "--agents", agents])
    assert exit_.value.code == 2
    assert f"--agents: '{agents}' {match}" in capsys.readouterr().err.splitlines()[-1]


def test_ship_refuses_an_agent_that_would_not_load(tmp_path):
    """Shipping checks the fingerprint as loading does: an agent whose env settings the
    env refuses, or whose observation differs from its env's, is not shipped."""
    run = _copy("sac", tmp_path / "run")
    meta = _meta(run)
    meta["env"]["kwargs"] = {"mesh": "thesis"}
    _set_meta(run, meta)
    with pytest.raises(AgentFileError, match="trained on another observation"):
        ship(run, "mine", tmp_path / "agents")
    meta["env"]["kwargs"] = {"sensor_noise": -1.0}
    _set_meta(run, meta)
    with pytest.raises(AgentFileError, match=rf"{META_FILE}: env: sensor_noise"):
        ship(run, "mine", tmp_path / "agents")
    assert not (tmp_path / "agents").exists()


def test_ship_onto_a_linked_name_replaces_the_link_not_its_target(tmp_path):
    elsewhere = _copy("vrs", tmp_path / "elsewhere")
    before = {p.name: p.read_bytes() for p in elsewhere.iterdir()}
    agents = tmp_path / "agents"
    agents.mkdir()
    (agents / "mine").symlink_to(elsewhere)
    with pytest.raises(FileExistsError, match="pass --force"):
        ship(_copy("sac", tmp_path / "run"), "mine", agents)
    ship(tmp_path / "run", "mine", agents, force=True)
    assert not (agents / "mine").is_symlink()
    assert TrainedAgent.load(agents / "mine").metadata["algo"] == "sac"
    assert {p.name: p.read_bytes() for p in elsewhere.iterdir()} == before


def test_ship_never_copies_a_linked_learning_curve(tmp_path):
    secret = tmp_path / "secret.txt"
    secret.write_text("a file elsewhere on the machine\n")
    run = _copy("sac", tmp_path / "run")
    (run / CURVE_FILE).unlink()
    (run / CURVE_FILE).symlink_to(secret)
    with pytest.raises(AgentFileError, match=rf"{CURVE_FILE}: is a symbolic link"):
        ship(run, "mine", tmp_path / "agents")
    assert not (tmp_path / "agents" / "mine").exists()


def test_a_folder_with_other_files_or_the_working_directory_is_not_replaced(tmp_path, monkeypatch):
    d = _copy("vrs", tmp_path / "a")
    (d / ".DS_Store").write_bytes(b"a desktop's")  # hidden files go with the folder
    assert check_replaceable(d) == d
    (d / "notes.txt").write_text("mine")
    agent = TrainedAgent.load(d)
    with pytest.raises(ValueError, match=r"holds \['notes.txt'\] besides an agent's files"):
        agent.save(d)
    agent.metadata["env"] = {"id": "evil_agent:ACLDBeam-v1"}  # never written: it would not load
    with pytest.raises(AgentFileError, match="env.id must be one of"):
        agent.save(tmp_path / "b")
    assert not (tmp_path / "b").exists()
    assert (d / "notes.txt").read_text() == "mine"
    (d / "notes.txt").unlink()
    monkeypatch.chdir(d)
    with pytest.raises(ValueError, match="holds the working directory"):
        check_replaceable(d)
    with pytest.raises(ValueError, match="name must be letters"):
        ship(d, "../x", tmp_path / "agents")


def _ship_under_ulimit(run: Path, agents: Path, kib: int) -> subprocess.CompletedProcess:
    """``python -m train.ship RUN mine --force`` with files limited to ``kib`` KiB (a full
    disk as the writer sees it: Python ignores SIGXFSZ, so a write past it fails EFBIG)."""
    cmd = (
        f"ulimit -f {kib} && exec {sys.executable} -m train.ship {run} mine "
        f"--agents {agents} --force"
    )
    env = dict(os.environ, PYTHONPATH=str(ROOT), OMP_NUM_THREADS="1")
    return subprocess.run(["bash", "-c", cmd], env=env, capture_output=True, text=True, timeout=300)


def test_a_disk_full_ship_leaves_the_old_agent_loadable_and_intact(tmp_path):
    """The disk fills after ``policy.npz`` and ``metadata.json`` (the new learning curve
    is larger than the limit): the old agent is still there, byte for byte, and loads; no
    temporary is left; the command says why in one line."""
    agents = tmp_path / "agents"
    old = _copy("vrs", agents / "mine")
    before = {p.name: p.read_bytes() for p in old.iterdir()}
    run = _copy("sac", tmp_path / "run")
    (run / CURVE_FILE).write_text("timesteps,case,ise\n" + "1000,1,1.0e-08\n" * 200_000)
    done = _ship_under_ulimit(run, agents, kib=1024)
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr
    assert done.stderr.splitlines()[-1].endswith(f"error: {agents / 'mine'}: File too large")
    assert {p.name: p.read_bytes() for p in old.iterdir()} == before
    assert TrainedAgent.load(old).metadata["algo"] == "vrs"
    assert [p.name for p in agents.iterdir()] == ["mine"]
    (run / CURVE_FILE).write_text("timesteps,case,ise\n1000,1,1.0e-08\n")
    assert _ship_under_ulimit(run, agents, kib=1024).returncode == 0  # room now: shipped
    assert TrainedAgent.load(old).metadata["algo"] == "sac"


def test_train_refuses_an_out_folder_with_other_files_before_training(tmp_path, capsys):
    """``python -m train`` writes its agent folder whole (replacing it), so an ``--out``
    holding the user's files is refused at once, not after the training."""
    from train.cli import main as train_main

    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    with pytest.raises(SystemExit) as exit_:
        train_main(["vrs", "--seed", "0", "--out", str(out)])
    assert exit_.value.code == 2
    err = capsys.readouterr().err.splitlines()[-1]
    assert "--out:" in err and "notes.txt" in err
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]


def test_curves_and_metadata_read_for_listings_are_checked(tmp_path):
    """``curve_rows`` reads every shipped curve as the csv module does and names a bad
    line; ``read_metadata`` checks as ``load`` does; ``ship`` refuses a damaged curve."""
    import csv

    for name in ("ppo", "sac", "vrs"):
        text = (AGENTS_DIR / name / CURVE_FILE).read_text()
        rows = curve_rows(text, name)
        ref = list(csv.DictReader(text.splitlines()))
        assert [(r["timesteps"], r["case"], r["ise"]) for r in rows] == [
            (int(r["timesteps"]), r["case"], float(r["ise"])) for r in ref
        ]
        assert read_metadata(AGENTS_DIR / name)["algo"] == name
    d, _ = _evil(tmp_path)
    with pytest.raises(AgentFileError, match="env.id must be one of"):
        read_metadata(d)
    run = _copy("sac", tmp_path / "run")
    (run / CURVE_FILE).write_text("timesteps,case,ise\n1000,1,1e-8\n1000,2,nan\n")
    with pytest.raises(AgentFileError, match=rf"{CURVE_FILE}: line 3: expected timesteps"):
        ship(run, "mine", tmp_path / "agents")
    assert not (tmp_path / "agents").exists()


def test_a_reader_sees_the_old_agent_or_the_new_one_never_a_mix(tmp_path):
    """Ships alternate ``vrs`` and ``sac`` onto one name while another thread loads it:
    every load has the weights of the agent its metadata names, and none fails."""
    import threading

    runs = {n: _copy(n, tmp_path / n) for n in ("vrs", "sac")}
    weights = {n: _arrays(d)["W0"] for n, d in runs.items()}
    agents = tmp_path / "agents"
    ship(runs["vrs"], "mine", agents)
    done = threading.Event()
    seen, errors = [], []

    def read():
        while not done.is_set():
            try:
                agent = TrainedAgent.load(agents / "mine", check=False)
            except Exception as exc:  # noqa: BLE001 (any failure is the finding)
                errors.append(exc)
                continue
            algo = agent.metadata["algo"]
            seen.append((algo, np.array_equal(agent.actor.arrays["W0"], weights[algo])))

    reader = threading.Thread(target=read)
    reader.start()
    try:
        for i in range(40):
            ship(runs["sac" if i % 2 == 0 else "vrs"], "mine", agents, force=True)
    finally:
        done.set()
        reader.join()
    assert errors == []
    assert len({algo for algo, _ in seen}) == 2 and all(same for _, same in seen)


def test_compare_lists_a_broken_agent_to_name_it_and_reads_curves_as_load_does(tmp_path, capsys):
    """``train.compare``'s listing keeps a folder whose metadata does not read (so that
    loading it names the fault: no silent skip, no traceback), and a learning curve that
    is a link is left out with one line."""
    from train.compare import agent_names, learning_curves_figure, load_agents

    agents = tmp_path / "agents"
    _copy("vrs", agents / "good")
    _set_meta(_copy("vrs", agents / "deep"), _deep(200_000))
    _set_meta(_copy("vrs", agents / "listed"), "[]")
    assert agent_names(agents) == ["deep", "good", "listed"]
    with pytest.raises(AgentFileError, match="deep/metadata.json: nested deeper"):
        load_agents(agents)
    secret = tmp_path / "secret.csv"
    secret.write_text("timesteps,case,ise\n1000,1,1e-8\n")
    (agents / "good" / CURVE_FILE).unlink()
    (agents / "good" / CURVE_FILE).symlink_to(secret)
    assert learning_curves_figure(load_agents(agents, ["good"])) is None
    assert "good: no learning curve" in capsys.readouterr().err


def test_benchmark_refuses_an_agent_folder_with_other_files_before_computing(tmp_path, capsys):
    """``python -m train.benchmark`` replaces each trial's agent folder whole: a folder in
    the way holding the user's files is refused at once, before the references."""
    from train.benchmark import main as benchmark_main

    folder = tmp_path / "out" / "agents" / "vrs-s0"
    folder.mkdir(parents=True)
    (folder / "notes.txt").write_text("mine")
    with pytest.raises(SystemExit) as exit_:
        benchmark_main(["--algos", "vrs", "--seeds", "0", "--out", str(tmp_path / "out")])
    assert exit_.value.code == 2
    err = capsys.readouterr().err.splitlines()[-1]
    assert "--out:" in err and "notes.txt" in err
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["agents"]


def test_without_descriptor_reads_links_and_fifos_are_still_refused(tmp_path, monkeypatch):
    """Where ``open`` takes no folder descriptor or ``O_NOFOLLOW`` (Windows), the reader
    checks each path without following it: the same refusals, the same agent."""
    import train.agent_files as agent_files

    monkeypatch.setattr(agent_files, "_BY_FD", False)
    d = _copy("vrs", tmp_path / "a")
    assert TrainedAgent.load(d).metadata["algo"] == "vrs"
    (d / POLICY_FILE).unlink()
    (d / POLICY_FILE).symlink_to(AGENTS_DIR / "sac" / POLICY_FILE)
    with pytest.raises(AgentFileError, match=rf"{POLICY_FILE}: is a symbolic link"):
        TrainedAgent.load(d, check=False)
    (d / POLICY_FILE).unlink()
    os.mkfifo(d / POLICY_FILE)
    with pytest.raises(AgentFileError, match=rf"{POLICY_FILE}: is not a regular file"):
        TrainedAgent.load(d, check=False)
