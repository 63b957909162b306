"""baselines.cases, the rows over named load cases, apart from the command
(baselines.evaluate, which re-exports them): the means of rows per policy, and the old
import paths handing out the same objects."""

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import baselines.evaluate as ev
from baselines import cases, marks, policies
from baselines.rollout import EvalRow

FIELDS = [f for f in EvalRow.__dataclass_fields__ if f not in ("case", "policy")]


def _row(policy: str, values: list[float]) -> EvalRow:
    return EvalRow(case=1, policy=policy, **dict(zip(FIELDS, values, strict=True)))


finite = st.floats(-1e6, 1e6, allow_nan=False)


@settings(max_examples=30, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.sampled_from("abc"), st.lists(finite, min_size=len(FIELDS), max_size=len(FIELDS))
        ),
        min_size=1,
        max_size=8,
    )
)
def test_mean_rows_are_the_mean_of_each_policy_s_rows(data):
    rows = [_row(p, v) for p, v in data]
    out = cases.mean_rows(rows, "random")
    assert [r.policy for r in out] == list(dict.fromkeys(p for p, _ in data))
    for r in out:
        mine = np.array([v for p, v in data if p == r.policy])
        for i, f in enumerate(FIELDS):
            assert r.case == "random"
            assert math.isclose(
                getattr(r, f), float(np.mean(mine[:, i])), rel_tol=1e-12, abs_tol=1e-9
            )


def test_the_command_re_exports_the_primitives():
    for name in ("episode_rows", "evaluate", "mean_rows"):
        assert getattr(ev, name) is getattr(cases, name)
    for name in ("policy_classes", "default_policies", "policies_for"):
        assert getattr(ev, name) is getattr(policies, name)
    assert ev.level_references is marks.level_references
