"""Independent restarts of a run (``TrainConfig.restarts``): the first run is the recipe's
own, the others have seeds of their own, and the trial returns the run whose selected check
has the lowest validation cost, with the budget of all runs and the learning curve of the
run returned (each run's curve kept beside its cost). With ``restart_above``, a run is
followed by another only if its cost is above that."""

import gymnasium as gym
import pytest

import acld_gym  # noqa: F401  (registers the envs)
from tests.train.tiny_sb3 import tiny_sac, tiny_sac_recipe
from train.core import algos, evaluate, threshold
from train.core.algos import restart_seeds, train_algo


def _cfg(restarts=2, select=True, timesteps=100, **fields):
    return tiny_sac(
        timesteps,
        restarts=restarts,
        select={"episodes": 2, "every": 50, "start": 0} if select else None,
        **fields,
    )


def _fake_runs(monkeypatch, costs):
    """``train_sb3`` replaced by runs whose chosen check costs ``costs[seed]``; returns the
    list the seeds of the runs trained are appended to."""
    calls = []

    def fake_train(cfg_, seed, env_id, timed, **_):
        calls.append(seed)
        timed(0, f"policy-{seed}")
        timed(cfg_.timesteps, f"policy-{seed}")
        return f"policy-{seed}", {
            "steps": cfg_.timesteps,
            "select": {"steps": 50, "cost": costs[seed]},
        }

    monkeypatch.setattr(algos, "train_sb3", fake_train)
    return calls


def test_restart_seeds_start_with_the_trial_seed_and_are_shared_by_no_other_trial():
    assert restart_seeds(7, 1) == [7]
    lists = {seed: restart_seeds(seed, 4) for seed in range(50)}
    assert all(s[0] == seed and len(set(s)) == 4 for seed, s in lists.items())
    every = [x for s in lists.values() for x in s]
    assert len(set(every)) == len(every)  # seed + k would give seed 0's run 2 to seed 1
    assert all(isinstance(x, int) and 0 <= x < 2**32 for x in every)
    assert (
        restart_seeds(7, 3) == restart_seeds(7, 3)
        and restart_seeds(7, 2) == restart_seeds(7, 3)[:2]
    )


def test_budget_counts_every_run():
    assert _cfg(restarts=3, timesteps=100).budget == 300 and _cfg(restarts=1).budget == 100


@pytest.mark.parametrize(
    "restarts, word", [(0, "restarts"), (True, "restarts"), (2.0, "restarts"), (65, "restarts")]
)
def test_bad_restarts_are_named(restarts, word):
    with pytest.raises(ValueError, match=word):
        _cfg(restarts=restarts)


def test_restarts_need_selection():
    with pytest.raises(ValueError, match="restarts: 2 runs need select"):
        _cfg(restarts=2, select=False)
    assert _cfg(restarts=1, select=False).restarts == 1


def test_the_run_with_the_lowest_validation_cost_is_returned(monkeypatch):
    cfg = _cfg(restarts=3)
    seeds = restart_seeds(5, 3)
    costs = dict(zip(seeds, (0.7, 0.5, 0.6), strict=True))  # the second run is the best
    calls = _fake_runs(monkeypatch, costs)
    seen = []

    def on_eval(steps, policy):
        seen.append((steps, policy))
        return {"policy": policy, "n": len(seen)}

    policy, record = train_algo(cfg, 5, "ACLDBeam-v1", on_eval)
    assert calls == seeds and policy == f"policy-{seeds[1]}"
    assert record["steps"] == 300 and record["select"]["cost"] == 0.5
    runs = record["restarts"]["runs"]
    assert record["restarts"]["chosen"] == 1
    assert [{k: r[k] for k in ("seed", "steps", "cost")} for r in runs] == [
        {"seed": s, "steps": 50, "cost": costs[s]} for s in seeds
    ]
    # every run is evaluated from its own step 0; each run's curve is its own policies'
    assert [s for s, _ in seen] == [0, 100] * 3
    for r in runs:
        assert [(p["steps"], p["policy"]) for p in r["curve"]] == [
            (0, f"policy-{r['seed']}"),
            (100, f"policy-{r['seed']}"),
        ]
    # the trial's curve is the returned run's: it ends at that run's policy, not the last run's
    assert record["curve"] == runs[1]["curve"] and record["curve"][-1]["n"] == 4


@pytest.mark.parametrize(
    "costs, trained, chosen",
    [
        ((0.52, 1.9, 0.51), 1, 0),  # a sound first run is the seed's: no restart
        ((1.94, 0.51, 0.4), 2, 1),  # a failed run is followed by one, which stops the runs
        ((1.0, 0.4, 0.3), 1, 0),  # at the threshold is not above it
        ((1.9, 1.2, 1.5), 3, 1),  # none below: every run, the lowest returned
    ],
)
def test_restart_above_retries_only_a_failed_run(monkeypatch, costs, trained, chosen):
    seeds = restart_seeds(5, 3)
    calls = _fake_runs(monkeypatch, dict(zip(seeds, costs, strict=True)))
    policy, record = train_algo(_cfg(restarts=3, restart_above=1.0), 5, "ACLDBeam-v1")
    assert calls == seeds[:trained] and policy == f"policy-{seeds[chosen]}"
    assert record["steps"] == 100 * trained and record["restarts"]["chosen"] == chosen
    assert [r["cost"] for r in record["restarts"]["runs"]] == list(costs[:trained])


@pytest.mark.parametrize("env_id", ["ACLDBeam-v1", "ACLDBeamHard-v1"])
@pytest.mark.parametrize("rule, ratio", [("lqr", 1.0), ("1.02 * lqg", 1.02)])
def test_restart_above_is_the_references_cost_on_the_selections_validation_loads(
    monkeypatch, capsys, env_id, rule, ratio
):
    seeds = restart_seeds(5, 3)
    calls = _fake_runs(monkeypatch, dict(zip(seeds, (0.55, 0.52, 0.5), strict=True)))
    asked = []

    def fake_reference(reference, env_id, loads):
        asked.append((reference, env_id, loads))
        return 0.535 / ratio

    monkeypatch.setattr(threshold, "reference_cost", fake_reference)
    policy, record = train_algo(_cfg(restarts=3, restart_above=rule), 5, env_id)
    # the first run is above the threshold (0.55 > 0.535): retried; the second is not
    assert calls == seeds[:2] and policy == f"policy-{seeds[1]}"
    reference = rule.split()[-1]
    assert asked == [(reference, env_id, evaluate.validation_seeds(2))]  # select's 2 loads
    rs = record["restarts"]
    assert rs["threshold"] == pytest.approx(0.535)
    assert rs["rule"] == {
        "threshold": rs["threshold"],
        "rule": f"{ratio:g} * {reference}",
        "ratio": ratio,
        "reference": reference,
        "reference_cost": 0.535 / ratio,
        "loads": 2,
    }
    # a retry is said, with its reason, on the console and in the record
    assert rs["retries"] == [rs["runs"][0]["retried"]] and "retried" not in rs["runs"][1]
    reason = rs["retries"][0]
    assert "validation cost 0.5500 above the threshold 0.5350" in reason
    assert f"{reference}'s {0.535 / ratio:.4f} on 2 validation loads" in reason
    out = capsys.readouterr().out
    assert f"retry: {reason}; training run 2" in out
    assert "retry threshold 0.5350" in out and "run 2 of up to 3" in out


def test_a_seed_whose_runs_all_miss_the_threshold_says_so(monkeypatch, capsys):
    seeds = restart_seeds(5, 3)
    _fake_runs(monkeypatch, dict(zip(seeds, (0.7, 0.6, 0.65), strict=True)))
    monkeypatch.setattr(threshold, "reference_cost", lambda *a: 0.5)
    _, record = train_algo(_cfg(restarts=3, restart_above="1.03 * lqg"), 5, "ACLDBeamLab-v1")
    rs = record["restarts"]
    assert len(rs["retries"]) == 2 and rs["chosen"] == 1  # the last run is not "retried"
    assert [r.split(":")[0] for r in rs["retries"]] == [
        f"run 1 (seed {seeds[0]})",
        f"run 2 (seed {seeds[1]})",
    ]
    out = capsys.readouterr().out
    assert out.count("retry: ") == 2
    assert "none of the 3 runs met it; the lowest returned, run 2 (0.6000)" in out


def test_lqr_validation_cost_is_the_lqr_policys():
    from baselines.policies import LQRPolicy

    seeds = evaluate.validation_seeds(2)
    lqr = LQRPolicy.for_env(gym.make("ACLDBeam-v1"))
    cost = evaluate.lqr_validation_cost("ACLDBeam-v1", seeds)
    assert cost == evaluate.validation_cost(lqr, "ACLDBeam-v1", seeds)
    assert 0.3 < cost < 1.0  # LQR controls: below the passive beam's 1


@pytest.mark.parametrize(
    "fields, match",
    [
        ({"restart_above": "smc"}, "restart_above must be '<ratio> \\* <reference>'"),
        ({"restart_above": "1.03 * mpc"}, "restart_above must be '<ratio> \\* <reference>'"),
        ({"restart_above": "1.03 *"}, "restart_above must be '<ratio> \\* <reference>'"),
        ({"restart_above": "x * lqg"}, "restart_above: the ratio must be a number"),
        ({"restart_above": "0 * lqg"}, "restart_above: the ratio must be finite and > 0"),
        ({"restart_above": "-1 * lqg"}, "restart_above: the ratio must be finite and > 0"),
        ({"restart_above": "nan * lqg"}, "restart_above: the ratio must be finite and > 0"),
        ({"restart_above": "inf * lqr"}, "restart_above: the ratio must be finite and > 0"),
        ({"restart_above": ["lqg"]}, "restart_above must be a finite real number"),
        ({"restarts": 1, "restart_above": "lqr"}, "restart_above needs restarts >= 2"),
        ({"restarts": 1, "restart_above": 1.0}, "restart_above needs restarts >= 2"),
        ({"restart_above": 0.0}, "restart_above must be > 0"),
        ({"restart_above": -1}, "restart_above must be > 0"),
        ({"restart_above": "1"}, "restart_above must be '<ratio> \\* <reference>'"),
        ({"restart_above": True}, "restart_above must be a finite real number"),
        ({"restart_above": float("nan")}, "restart_above must be a finite real number"),
    ],
)
def test_bad_restart_above_is_named(fields, match):
    with pytest.raises(ValueError, match=match):
        _cfg(**{"restarts": 2, **fields})
    assert _cfg(restarts=2, restart_above=1.0).budget == 200  # the most a seed may take


def test_a_run_whose_curve_stops_short_gets_a_last_point(monkeypatch):
    monkeypatch.setattr(
        algos,
        "train_sb3",
        lambda cfg, seed, env_id, timed, **_: (
            timed(0, "p0"),
            ("p", {"steps": cfg.timesteps}),
        )[1],
    )
    policy, record = train_algo(
        _cfg(restarts=1, select=False), 3, "ACLDBeam-v1", lambda s, p: {"policy": p}
    )
    assert record["curve"] == [{"steps": 0, "policy": "p0"}, {"steps": 100, "policy": "p"}]
    _, record = train_algo(_cfg(restarts=1, select=False), 3, "ACLDBeam-v1")
    assert record["curve"] == []  # no callback, no curve


def test_one_run_is_the_plain_recipe(monkeypatch):
    seen = []
    monkeypatch.setattr(
        algos,
        "train_sb3",
        lambda cfg, seed, env_id, timed, **_: (
            seen.append(seed) or "p",
            {"steps": cfg.timesteps, "select": {"steps": 0, "cost": 1}},
        ),
    )
    policy, record = train_algo(_cfg(restarts=1), 11, "ACLDBeam-v1")
    assert seen == [11] and policy == "p" and "restarts" not in record


def test_two_tiny_sac_runs_return_the_better_one():
    """Real runs: the returned policy scores its run's chosen validation cost again, and
    that cost is the lower of the two runs'."""
    cfg = tiny_sac_recipe(600, restarts=2, select={"episodes": 2, "every": 200, "start": 0})
    policy, record = train_algo(cfg, 0, "ACLDBeam-v1")
    runs = record["restarts"]["runs"]
    assert [r["seed"] for r in runs] == restart_seeds(0, 2) and record["steps"] >= 1200
    assert record["select"]["cost"] == min(r["cost"] for r in runs)
    assert runs[0]["cost"] != runs[1]["cost"]  # independent runs
    again = evaluate.validation_cost(policy, "ACLDBeam-v1", evaluate.validation_seeds(2))
    assert again == pytest.approx(record["select"]["cost"], rel=1e-5)


@pytest.mark.parametrize(
    "restart_above, trained",
    [(1e-9, 3), (1e9, 1)],  # no run meets it: all three, the lowest; the first meets it
)
def test_runs_at_once_are_the_runs_one_after_another(restart_above, trained):
    """``workers=2`` trains the runs in worker processes, two at once: the same runs, taken
    in the same order, so the same policy (parameters and actions) and record; a run
    started ahead and not needed is ended and counted nowhere but in the CPU time.

    The worker pool's semaphores are released before ``train_algo`` returns, not when the
    garbage collector next runs: in a Ray Tune trial that is at the process's exit, after
    Ray has ended its resource tracker, which then printed a KeyError traceback for each
    (the pool's objects hold one another in cycles)."""
    import gc
    from multiprocessing.synchronize import SemLock

    import numpy as np
    import torch

    from train.core.trials import CaseISE

    def semaphores():
        return {id(o) for o in gc.get_objects() if issubclass(type(o), SemLock)}

    cfg = tiny_sac_recipe(
        400,
        restarts=3,
        restart_above=restart_above,
        select={"episodes": 2, "every": 400, "start": 0},
    )
    curve = CaseISE("ACLDBeam-v1", evaluate.eval_episodes(1))  # pickles to the workers
    p1, r1 = train_algo(cfg, 3, "ACLDBeam-v1", curve, workers=1)
    gc.collect()
    before = semaphores()
    gc.disable()  # only the release under test may collect the pool's cycles
    try:
        p2, r2 = train_algo(cfg, 3, "ACLDBeam-v1", curve, workers=2)
        left = semaphores() - before
    finally:
        gc.enable()
    assert not left, f"{len(left)} semaphores of the worker pool still alive"
    assert len(r1["restarts"]["runs"]) == trained and r1["steps"] == 400 * trained
    assert "workers" not in r1["restarts"] and r2["restarts"].pop("workers") == 2
    for key in ("steps", "select", "curve", "restarts"):
        assert r2[key] == r1[key], key
    s1, s2 = p1.model.policy.state_dict(), p2.model.policy.state_dict()
    assert s1.keys() == s2.keys() and all(torch.equal(s1[k], s2[k]) for k in s1)
    n_obs = gym.make("ACLDBeam-v1").observation_space.shape[0]
    obs = (np.random.default_rng(0).normal(size=(8, n_obs)) * 1e-4).astype(np.float32)
    assert np.array_equal(p1.predict(obs)[0], p2.predict(obs)[0])
    assert not hasattr(p2.model, "replay_buffer")  # the worker sent the policy alone
    assert r2["train_seconds"] > 0
    # the workers' CPU time is counted (this process only waits for them)
    assert r2["train_cpu_seconds"] > 0.5 * r1["train_cpu_seconds"] > 0


def test_a_run_in_this_process_has_one_blas_thread_as_a_worker_has(monkeypatch):
    """Whatever the caller's BLAS threads, a run trains on one, as a worker process's does:
    on some CPUs' kernels one thread and two round differently, so a run would otherwise
    depend on how it was called (an AMD EPYC with OpenBLAS's Haswell kernels: the test
    above failed there by one ulp of a validation cost)."""
    from threadpoolctl import threadpool_info, threadpool_limits

    seen = []

    def fake_train(cfg_, seed, env_id, timed, **_):
        seen.append([d["num_threads"] for d in threadpool_info() if d["user_api"] == "blas"])
        return "policy", {"steps": cfg_.timesteps, "select": {"steps": 50, "cost": 1.0}}

    monkeypatch.setattr(algos, "train_sb3", fake_train)
    with threadpool_limits(limits=2, user_api="blas"):
        train_algo(_cfg(restarts=1), 0, "ACLDBeam-v1")
        after = [d["num_threads"] for d in threadpool_info() if d["user_api"] == "blas"]
    assert seen and all(n == 1 for n in seen[0])
    assert after == [min(2, d) for d in after]  # the caller's setting is back afterwards


@pytest.mark.parametrize("workers", [0, -1, 1.5, True, "2"])
def test_bad_workers_are_named(workers):
    with pytest.raises(ValueError, match="workers must be a positive integer"):
        train_algo(_cfg(restarts=2), 0, "ACLDBeam-v1", workers=workers)


def test_a_portable_policy_pickles_after_a_training_step_and_acts_the_same():
    """What a worker sends back: the policy without its model's env and buffer, through
    the pickler a process pool sends results with (torch's shared-memory tensor reductions
    refuse the tensors autograd still holds, gSDE's last noise draw), acting the same."""
    import pickle
    from multiprocessing.reduction import ForkingPickler

    import numpy as np

    from tests.train.tiny_sb3 import tiny_ppo
    from train.core.sb3_train import train_sb3

    policy, _ = train_sb3(tiny_ppo(), 0, "ACLDBeam-v1")
    n_obs = gym.make("ACLDBeam-v1").observation_space.shape[0]
    obs = (np.random.default_rng(1).normal(size=(6, n_obs)) * 1e-4).astype(np.float32)
    net = policy.model.policy
    net.log_std.requires_grad_(True)  # as while training (the recipe's annealing freezes it)
    net.reset_noise(4)  # gSDE's draw of a rollout: exploration matrices attached to log_std
    with pytest.raises(RuntimeError, match="non-leaf tensor"):
        ForkingPickler.dumps(net)  # as a worker sends its result (torch's tensor reductions)
    back = pickle.loads(ForkingPickler.dumps(policy.portable()))
    assert np.array_equal(back.predict(obs)[0], policy.predict(obs)[0])
    assert not hasattr(back.model, "env") and len(pickle.dumps(back)) < 200_000
