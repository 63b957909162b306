"""A damaged plant file in the user cache is rebuilt, never read half-way (issue 65): every
member is checked (names, declared sizes, dtype, shape, finiteness, the JSON meta's fields)
and any damage is the package's DataFileError, which ``cached`` turns into a rebuild and
one line on stderr."""

from __future__ import annotations

import dataclasses
import io
import json
import zipfile

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from acld_gym.physics import plant_cache
from acld_gym.physics.params import BeamParameters
from acld_gym.physics.truth import plant
from acld_gym.util.validate import DataFileError

PARAMS = dataclasses.replace(BeamParameters(), ghm_zeta=4.5)
GOOD = plant("thesis")
GOOD = dataclasses.replace(GOOD, params=PARAMS)


def _good_bytes(tmp_path) -> bytes:
    path = tmp_path / "good.npz"
    plant_cache.save(GOOD, path)
    return path.read_bytes()


def _members(data: bytes) -> dict:
    with np.load(io.BytesIO(data), allow_pickle=False) as z:
        return {k: z[k] for k in z.files}


def _npz(members: dict) -> bytes:
    buf = io.BytesIO()
    np.savez(buf, **members)
    return buf.getvalue()


def _meta(**changes) -> np.ndarray:
    meta = {
        "name": GOOD.name,
        "provenance": {},
        "params": dataclasses.asdict(PARAMS),
    } | changes
    return np.frombuffer(json.dumps(meta).encode(), np.uint8)


def _rebuilt(tmp_path, monkeypatch, capsys, data: bytes) -> str:
    """Write ``data`` as the cache file of PARAMS; ``cached`` must rebuild and say so in one
    line naming the file."""
    monkeypatch.setenv("ACLD_GYM_CACHE_DIR", str(tmp_path / "cache"))
    cache = tmp_path / "cache"
    cache.mkdir(exist_ok=True)
    path = cache / f"plant-converged-{plant_cache.key(PARAMS, 1e-3, 128)}.npz"
    path.write_bytes(data)
    calls = []

    def build():
        calls.append(1)
        return GOOD

    assert plant_cache.cached(PARAMS, 1e-3, 128, build) is GOOD
    assert calls == [1]
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "rebuilding the plant" in err and str(path) in err, err
    # rewritten whole: read back as it was built
    again = plant_cache.load(path)
    assert np.array_equal(again.Fd, GOOD.Fd) and again.params == PARAMS
    return err


def test_a_good_file_reads_back_exactly(tmp_path):
    path = tmp_path / "p.npz"
    plant_cache.save(GOOD, path)
    got = plant_cache.load(path)
    assert got.params == PARAMS and got.name == GOOD.name
    for name, U in GOOD.units.items():
        assert np.array_equal(got.units[name], U)
    assert np.array_equal(got.node_w, GOOD.node_w)


def _damaged(name):
    """The good members with one change (None: the member removed)."""

    def make(members):
        out = dict(members)
        value = CHANGES[name](members)
        key = name.split("/")[0]
        if value is None:
            out.pop(key)
        else:
            out[key] = value
        return out

    return make


CHANGES = {
    # the probe's: a JSON list, deep nesting, unknown parameters
    "meta/list": lambda m: np.frombuffer(b"[1]", np.uint8),
    "meta/deep": lambda m: np.frombuffer(b"[" * 50000 + b"]" * 50000, np.uint8),
    "meta/bogus": lambda m: _meta(params={"bogus": 1}),
    "meta/missing-field": lambda m: _meta(
        params={k: v for k, v in dataclasses.asdict(PARAMS).items() if k != "length"}
    ),
    "meta/string-value": lambda m: _meta(params=dataclasses.asdict(PARAMS) | {"length": "0.3"}),
    "meta/bool-value": lambda m: _meta(params=dataclasses.asdict(PARAMS) | {"length": True}),
    "meta/negative": lambda m: _meta(params=dataclasses.asdict(PARAMS) | {"length": -1.0}),
    "meta/other-params": lambda m: _meta(params=dataclasses.asdict(BeamParameters())),
    "meta/name": lambda m: _meta(name=3),
    "meta/provenance": lambda m: _meta(provenance=[1]),
    "meta/not-utf8": lambda m: np.frombuffer(b"\xff\xfe", np.uint8),
    "meta/floats": lambda m: np.zeros(3),
    "meta/missing": lambda m: None,
    "Fd/missing": lambda m: None,
    "Fd/ints": lambda m: m["Fd"].astype(np.int64),
    "Fd/matrix": lambda m: m["Fd"][:, None],
    "Fd/empty": lambda m: m["Fd"][:0],
    "c/short": lambda m: m["c"][:-1],
    "piezo/nan": lambda m: np.where(np.arange(m["piezo"].size) == 0, np.nan, m["piezo"]),
    "physical/wide": lambda m: np.hstack([m["physical"], m["physical"][:, :1]]),
    "node_w/rows": lambda m: m["node_w"][:-1],
    "unit:beam.inertia/inf": lambda m: np.full_like(m["unit:beam.inertia"], np.inf),
    "unit:beam.inertia/missing": lambda m: None,
    "unit:bogus.term/extra": lambda m: np.eye(2),
    "node_x/strings": lambda m: np.array(["a", "b"]),
}


@pytest.mark.parametrize("name", sorted(CHANGES))
def test_a_damaged_member_is_rebuilt(name, tmp_path, monkeypatch, capsys):
    members = _damaged(name)(_members(_good_bytes(tmp_path)))
    data = _npz(members)
    path = tmp_path / "d.npz"
    path.write_bytes(data)
    if name == "meta/other-params":  # a well-formed plant, but not the one of its key
        assert plant_cache.load(path).params == BeamParameters()
    else:
        with pytest.raises(DataFileError):
            plant_cache.load(path)
    _rebuilt(tmp_path, monkeypatch, capsys, data)


def test_a_header_declaring_more_than_its_data_is_refused_before_reading(tmp_path):
    # An array's memory is taken from its header: a header of 10^12 entries is refused
    # from the archive's directory and the header alone.
    good = _good_bytes(tmp_path)
    src = zipfile.ZipFile(io.BytesIO(good))
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as out:
        for info in src.infolist():
            data = src.read(info)
            if info.filename == "Fd.npy":
                head = io.BytesIO()
                np.lib.format.write_array_header_1_0(
                    head, {"descr": "<f8", "fortran_order": False, "shape": (10**12,)}
                )
                data = head.getvalue() + b"\0" * 64
            out.writestr(info.filename, data)
    path = tmp_path / "h.npz"
    path.write_bytes(buf.getvalue())
    with pytest.raises(DataFileError, match="Fd: its header"):
        plant_cache.load(path)


@pytest.mark.parametrize("data", [b"", b"x", b"PK\x03\x04 truncated"])
def test_a_file_that_is_not_an_archive_is_rebuilt(data, tmp_path, monkeypatch, capsys):
    _rebuilt(tmp_path, monkeypatch, capsys, data)


@settings(
    max_examples=60,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(
    cut=st.integers(0, 200_000),
    flips=st.lists(st.tuples(st.integers(0, 200_000), st.integers(1, 255)), max_size=3),
)
def test_fuzz_truncated_or_flipped_files_load_or_raise_the_packages_error(tmp_path, cut, flips):
    data = bytearray(_good_bytes(tmp_path))
    for at, x in flips:
        data[at % len(data)] ^= x
    data = bytes(data[: cut % (len(data) + 1)]) if cut % 3 == 0 else bytes(data)
    path = tmp_path / "f.npz"
    path.write_bytes(data)
    try:
        got = plant_cache.load(path)
    except DataFileError:
        return
    # a file that loads is a plant of the checked form
    r = got.Fd.shape[0]
    assert all(U.shape == (r, r) and np.all(np.isfinite(U)) for U in got.units.values())
    assert isinstance(got.params, BeamParameters)
