r"""The maps of the package's wrappers, one implementation each, shared by the single-env
wrappers (:mod:`acld_gym.wrappers.single`) and their vector versions
(:mod:`acld_gym.wrappers.vector`): each is built from the wrapped env's spaces (and, for
:class:`ModeSlots`, its configuration), checks them once, and maps one row or a batch of rows
(the leading axes) with the same elementwise arithmetic, so a sub-env of a vector env gets
bit for bit what a single env gets.

* :class:`UnitMap`: action :math:`a \in [-1, 1]` to volts, :math:`V = k\,v_{max}\,a`.
* :class:`ModeSlots`: the ``"estimate"`` observation's slots of the first modes and the tip.
* :class:`LinearMap`: :math:`[T^T z_{:d}, z_{d:}]`, a fixed linear map (e.g. :func:`whitening`).
"""

from __future__ import annotations

import numpy as np
from gymnasium import spaces

__all__ = [
    "UnitMap",
    "ModeSlots",
    "LinearMap",
    "whitening",
    "check_headroom",
    "MAX_HEADROOM",
]

#: Largest ``headroom`` of :class:`acld_gym.wrappers.UnitAction` and the training configs
#: (the limit at a = 0.01).
MAX_HEADROOM = 100.0


def check_headroom(headroom, name: str = "headroom") -> float:
    """``headroom`` as a float in [1, :data:`MAX_HEADROOM`], or ``ValueError`` naming it
    (as ``name``)."""
    from acld_gym.util.validate import check_real

    try:
        return check_real(name, headroom, 1.0, MAX_HEADROOM)
    except ValueError:
        raise ValueError(
            f"{name} must be a number in [1, {MAX_HEADROOM:g}] (the action "
            f"range over the actuator's), got {headroom!r}"
        ) from None


class UnitMap:
    r"""Action :math:`a \in [-1, 1]` to voltage :math:`V = k\,v_{max}\,a` [V], in float64.

    Parameters
    ----------
    action_space : spaces.Box
        The wrapped env's action space (one sub-env's): a symmetric 1-D Box
        :math:`[-v_{max}, v_{max}]` [V] of shape (1,).
    headroom : float
        k in [1, :data:`MAX_HEADROOM`] (dimensionless): the actuator's limit is the action
        :math:`\pm 1/k`.
    owner : str
        The wrapper's name, for the error message.

    Attributes
    ----------
    headroom, v_max : float
        k and :math:`v_{max}` [V].
    space : spaces.Box
        ``Box(-1, 1, (1,), float32)``, the action space one sub-env offers.
    """

    def __init__(self, action_space, headroom: float = 1.0, owner: str = "UnitAction"):
        box = action_space
        if not (
            isinstance(box, spaces.Box)
            and box.shape == (1,)
            and np.all(box.low == -box.high)
            and np.all(box.high > 0)
        ):
            raise ValueError(
                f"env: {owner} needs a symmetric 1-D Box action space (-v_max, v_max), got {box!r}"
            )
        self.headroom = check_headroom(headroom)
        self.v_max = float(box.high[0])
        self.space = spaces.Box(-1.0, 1.0, (1,), np.float32)

    def __call__(self, action) -> np.ndarray:
        """Volts [V] (float64, same shape) for actions in [-1, 1]."""
        return (self.headroom * self.v_max) * np.asarray(action, dtype=np.float64)

    def inverse(self, volts) -> np.ndarray:
        """The action (float32) of voltages [V]: exact for every float32 action when
        :math:`k v_{max}` is a small integer times a power of two."""
        return (np.asarray(volts, dtype=np.float64) / (self.headroom * self.v_max)).astype(
            np.float32
        )


class ModeSlots:
    """The ``"estimate"`` observation's entries of the first ``modes`` modes and the tip
    (:func:`acld_gym.envs.step.estimate_slots`), then any appended entries (the commands
    in flight of ``observe_commands``, ``log c`` of ``observe_reward_scale``) as they are.

    Parameters
    ----------
    config : EnvConfig or None
        The wrapped ACLDBeam env's configuration (:class:`acld_gym.envs.config.EnvConfig`;
        None: not an ACLDBeam env, refused).
    shape : tuple of int
        The shape of one observation of the wrapped env, which must be the env's own.
    modes : int
        How many modes to keep, 1 .. the design model's (4 on the converged mesh).
    owner : str
        The wrapper's name, for the error messages.

    Attributes
    ----------
    slots : numpy.ndarray
        The indices kept, in order.
    space : spaces.Box
        The observation space of one sub-env after the map (float32, unbounded).
    """

    def __init__(self, config, shape, modes: int = 2, owner: str = "ObserveModes"):
        if config is None or config.obs_mode != "estimate":
            raise ValueError(f"env: {owner} needs an ACLDBeam env with obs_mode='estimate'")
        if isinstance(modes, bool) or not isinstance(modes, (int, np.integer)):
            raise ValueError(f"modes must be an integer, got {modes!r}")
        from acld_gym.envs.step import appended_size, estimate_slots, observation_size

        # the layout's owner (acld_gym.envs.step) says where the modes are and how many
        nom = config.nominal()
        base = observation_size(nom, config.obs_mode)
        n = base + appended_size(config)
        if tuple(shape) != (n,):
            raise ValueError(
                f"env: {owner} needs the ACLDBeam env's own observation of "
                f"{n} entries, got shape {tuple(shape)} (wrap it "
                f"before any wrapper that changes the observation)"
            )
        self.modes = int(modes)
        self.slots = np.r_[estimate_slots(nom.design.reduced.order, self.modes), np.arange(base, n)]
        self.space = spaces.Box(-np.inf, np.inf, (len(self.slots),), np.float32)

    def __call__(self, observation) -> np.ndarray:
        """The kept entries (float32) of one observation or a batch (last axis)."""
        return np.asarray(observation, dtype=np.float32)[..., self.slots]


class LinearMap:
    r"""Observation ``z`` to :math:`[T^T z_{:d}, z_{d:}]` (float32): a fixed d x d matrix T
    on the first d entries, the last ``passthrough`` as they are.

    The product is summed term by term in a fixed order (:meth:`mix`), not by BLAS, whose
    rounding of a row depends on the batch's size: a row of a batch maps exactly as the
    row alone.

    Parameters
    ----------
    shape : tuple of int
        The shape (n,) of one observation of the wrapped env.
    transform : array_like
        T, a finite (d, d) matrix, d = n - ``passthrough`` (units: those of the observation
        entries it mixes; :func:`whitening` gives a dimensionless one for the env's scaled
        observation).
    passthrough : int
        How many trailing entries pass unchanged, in [0, n).

    Attributes
    ----------
    transform : numpy.ndarray
        T in float64.
    passthrough : int
        How many trailing entries pass unchanged (the argument, as an int).
    space : spaces.Box
        The observation space of one sub-env after the map (float32, unbounded).
    """

    def __init__(self, shape, transform, passthrough: int = 0):
        if len(shape) != 1:
            raise ValueError(f"env: the observation must be 1-D to transform, got shape {shape}")
        n = int(shape[0])
        if (
            isinstance(passthrough, bool)
            or not isinstance(passthrough, (int, np.integer))
            or not 0 <= passthrough < n
        ):
            raise ValueError(f"passthrough must be an integer in [0, {n}), got {passthrough!r}")
        d = n - int(passthrough)
        T = np.asarray(transform, dtype=np.float64)
        if T.shape != (d, d) or not np.all(np.isfinite(T)):
            raise ValueError(f"transform must be a finite ({d}, {d}) matrix, got shape {T.shape}")
        self.transform, self.passthrough, self._d = T, int(passthrough), d
        self.space = spaces.Box(-np.inf, np.inf, (n,), np.float32)

    def mix(self, observation) -> np.ndarray:
        r""":math:`T^T z_{:d}` in float64 for one observation or a batch (last axis), summed
        as :math:`\sum_k z_k T_{k,:}`, k ascending: row by row the same numbers at any batch
        size (a BLAS product of a batch rounds its rows otherwise than of a row alone)."""
        z = np.asarray(observation, dtype=np.float64)
        T = self.transform
        u = z[..., 0, None] * T[0]
        for k in range(1, self._d):
            u = u + z[..., k, None] * T[k]
        return u

    def __call__(self, observation) -> np.ndarray:
        """The map of one observation or a batch (last axis), float32."""
        z = np.asarray(observation, dtype=np.float64)
        return np.concatenate([self.mix(z), z[..., self._d :]], axis=-1).astype(np.float32)


def whitening(directions: np.ndarray, ridge: float = 1e-3) -> np.ndarray:
    r"""ZCA whitening matrix :math:`T = \Sigma^{-1/2}` (ridge-regularised, relative to the
    largest eigenvalue) of the second moment of the observation directions ``z/|z|``
    (rows), so that the direction features of ``z @ T`` are isotropic on average."""
    u = np.asarray(directions, dtype=np.float64)
    if u.ndim != 2 or u.shape[0] < 1 or not np.all(np.isfinite(u)):
        raise ValueError(
            f"directions must be a finite (n, d) array with n >= 1, got shape {u.shape}"
        )
    sigma = u.T @ u / u.shape[0]
    lam, vec = np.linalg.eigh(sigma)
    lam = np.maximum(lam, 0.0) + ridge * lam.max()
    return (vec / np.sqrt(lam)) @ vec.T
