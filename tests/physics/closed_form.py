r"""Closed-form reference results for the finite-element verification tests.

This module is test infrastructure, not part of the package: it deliberately shares
no code with :mod:`acld_gym` (only numpy/scipy), so that the tests in
``test_verification.py`` compare the FE model with independently derived results.
SI units throughout: m, kg, s, N, Pa = N/m^2, rad/s.

Contents and sources
--------------------
1. Uniform cantilever, Euler-Bernoulli theory: :math:`\omega_n = (\beta_n L)^2
   \sqrt{EI/(\rho A L^4)}` with :math:`1 + \cos\beta L \cosh\beta L = 0`
   (Rayleigh, *Theory of Sound*, 1877; tabulated e.g. in Thomson, *Theory of
   Vibration with Applications*, App. D.3: 1.8751, 4.6941, 7.8548).
2. Uniform cantilever, Timoshenko theory (rotary inertia and shear, Timoshenko 1921):
   frequency equation of the clamped-free beam as the characteristic determinant of
   the general solution (the same construction as Huang 1961, J. Appl. Mech. 28,
   579-584, and Han, Benaroya & Wei 1999, J. Sound Vib. 225(5), 935-988,
   clamped-free case), reduced by hand to a 2 x 2 determinant, see
   :func:`timoshenko_cantilever_determinant`.
3. Static tip deflection of a Timoshenko cantilever under a tip load,
   :math:`P L^3/(3EI) + P L/(kGA)` (e.g. Timoshenko & Gere, *Mechanics of
   Materials*; Reddy 1997, Comput. Methods Appl. Mech. Eng. 149, 113-132), and the
   closed form of the discretisation error of the linear element with one-point
   (reduced) shear integration (derived in :func:`reduced_integration_tip_deflection`).
4. GHM shear modulus, :math:`G(s) = \kappa [1 + \alpha (s^2 + 2\zeta\hat\omega s)
   / (s^2 + 2\zeta\hat\omega s + \hat\omega^2)]` (Golla & Hughes 1985, J. Appl.
   Mech. 52, 897-906; thesis eq. (20), whose left-hand side ``s G(s)`` is the
   Laplace transform of the relaxation function).
5. Three-layer sandwich beam with a viscoelastic core (layer 1 = base, 2 = core,
   3 = constraining layer):

   * the Ross-Kerwin-Ungar (RKU) complex flexural rigidity (Ross, Ungar & Kerwin
     1959, "Damping of plate flexural vibrations by means of viscoelastic laminae",
     in *Structural Damping*, ASME; also reproduced in Nashif, Jones & Henderson 1985,
     *Vibration Damping*, Wiley), :func:`rku_flexural_rigidity`;
   * the sixth-order equation of Mead & Markus (1969, "The forced vibration of a
     three-layer, damped sandwich beam with arbitrary boundary conditions",
     J. Sound Vib. 10(2), 163-175), :func:`mead_markus_flexural_rigidity`, solved
     exactly (transfer matrix of the equivalent first-order system) for the
     boundary conditions of the FE model's cantilever: base layer clamped,
     constraining layer free at both ends (:func:`mead_markus_pole`; Mead & Markus
     1970, J. Sound Vib. 12(1), 99-112, give such solutions for clamped beams).

   Both share the Mead-Markus/RKU assumptions: Euler-Bernoulli face layers with a
   common deflection w (no face shear, no rotary or longitudinal inertia), a core
   that carries shear only (no extension, no bending; its mass moves with w), linear
   viscoelasticity. The equation numbers of the originals could not be checked when
   this module was written (no copy at hand), so every equation is written out in
   full in the docstrings instead, and each is cross-checked in
   ``test_verification.py`` (RKU = Mead-Markus for E2 = 0; the transfer-matrix
   solution reproduces RKU exactly for pinned-pinned supports; limits G -> 0).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
from scipy.optimize import brentq

__all__ = [
    "cantilever_beta_l",
    "euler_bernoulli_cantilever",
    "timoshenko_wavenumbers",
    "timoshenko_cantilever_determinant",
    "timoshenko_cantilever_frequencies",
    "timoshenko_tip_deflection",
    "reduced_integration_tip_deflection",
    "ghm_modulus",
    "Sandwich",
    "rku_flexural_rigidity",
    "mead_markus_flexural_rigidity",
    "loss_factor",
    "rku_pole",
    "mead_markus_determinant",
    "mead_markus_pole",
    "SUPPORTS",
]


# --- 1. Euler-Bernoulli cantilever ------------------------------------------------


def cantilever_beta_l(n: int = 3) -> np.ndarray:
    """The first ``n`` roots of :math:`1 + \\cos x \\cosh x = 0` (clamped-free EB beam),
    1.87510407, 4.69409113, 7.85475744, ... (dimensionless)."""
    f = lambda x: 1.0 + np.cos(x) * np.cosh(x)  # noqa: E731
    # exactly one root in each [(j - 1) pi, j pi]: cos x changes sign once there
    return np.array([brentq(f, (j - 1) * np.pi, j * np.pi, xtol=1e-15) for j in range(1, n + 1)])


def euler_bernoulli_cantilever(
    E: float, I: float, rho: float, A: float, L: float, n: int = 3
) -> np.ndarray:
    """Natural frequencies [rad/s] of a uniform EB cantilever,
    :math:`(\\beta_n L)^2 \\sqrt{EI/(\\rho A L^4)}`; E [Pa], I [m^4], rho [kg/m^3],
    A [m^2], L [m]."""
    return cantilever_beta_l(n) ** 2 * np.sqrt(E * I / (rho * A * L**4))


# --- 2. Timoshenko cantilever -------------------------------------------------------


def timoshenko_wavenumbers(
    omega: float, E: float, G: float, k: float, rho: float, A: float, I: float
) -> tuple[float, float]:
    r"""Wavenumbers :math:`(\alpha, \beta)` [1/m] of a Timoshenko beam at ``omega`` below
    the cut-off :math:`\sqrt{kGA/(\rho I)}`.

    Equations of motion (Timoshenko 1921), with shear force :math:`Q = kGA(w' - \theta)`
    and bending moment :math:`M = EI\theta'`:

    .. math::

        kGA(w'' - \theta') + \rho A \omega^2 w = 0, \qquad
        EI\theta'' + kGA(w' - \theta) + \rho I \omega^2 \theta = 0 .

    With :math:`e^{sx}` solutions, :math:`\lambda = s^2` solves
    :math:`\lambda^2 + \omega^2 \rho (1/E + 1/(kG)) \lambda
    + (\rho A \omega^2/EI)(\rho I \omega^2/(kGA) - 1) = 0`, one root
    :math:`\alpha^2 > 0` and one :math:`-\beta^2 < 0` below the cut-off.
    """
    b1 = omega**2 * rho * (1.0 / E + 1.0 / (k * G))
    c0 = rho * A * omega**2 / (E * I) * (rho * I * omega**2 / (k * G * A) - 1.0)
    if c0 >= 0.0:
        raise ValueError("omega is above the Timoshenko cut-off frequency")
    disc = np.sqrt(b1**2 - 4.0 * c0)
    return float(np.sqrt(0.5 * (-b1 + disc))), float(np.sqrt(0.5 * (b1 + disc)))


def timoshenko_cantilever_determinant(
    omega: float, E: float, G: float, k: float, rho: float, A: float, I: float, L: float
) -> float:
    r"""Frequency function of the clamped-free Timoshenko beam (zero at a natural
    frequency ``omega`` [rad/s]).

    General solution below the cut-off (:func:`timoshenko_wavenumbers`):

    .. math::

        w = C_1\cosh\alpha x + C_2\sinh\alpha x + C_3\cos\beta x + C_4\sin\beta x, \\
        \theta = k_\alpha (C_1\sinh\alpha x + C_2\cosh\alpha x)
               + k_\beta (-C_3\sin\beta x + C_4\cos\beta x),

    with :math:`k_\alpha = (\alpha^2 + \rho\omega^2/kG)/\alpha`,
    :math:`k_\beta = (\beta^2 - \rho\omega^2/kG)/\beta` (from the first equation).
    Clamp :math:`w(0) = \theta(0) = 0` gives :math:`C_1 = -C_3`,
    :math:`C_2 = -(k_\beta/k_\alpha) C_4`; the free end :math:`\theta'(L) = 0`
    (no moment) and :math:`w'(L) - \theta(L) = 0` (no shear force) leave the 2 x 2
    determinant returned here (with :math:`a = \alpha L`, :math:`b = \beta L`):

    .. math::

        D = (k_\alpha\alpha\cosh a + k_\beta\beta\cos b)
            \left(\tfrac{k_\beta}{k_\alpha}(\alpha - k_\alpha)\cosh a
                  - (\beta - k_\beta)\cos b\right)
          - k_\beta(\alpha\sinh a + \beta\sin b)((\alpha - k_\alpha)\sinh a
            + (\beta - k_\beta)\sin b).

    For :math:`G \to \infty`, :math:`I\rho \to 0` it reduces to a multiple of
    :math:`1 + \cos\beta L\cosh\beta L`.
    """
    al, be = timoshenko_wavenumbers(omega, E, G, k, rho, A, I)
    r = rho * omega**2 / (k * G)
    ka = (al**2 + r) / al
    kb = (be**2 - r) / be
    a, b = al * L, be * L
    # alpha - k_alpha = -r/alpha and beta - k_beta = r/beta, written so (no cancellation
    # in the slender limit r << alpha^2, beta^2)
    dka, dkb = -r / al, r / be
    a11 = ka * al * np.cosh(a) + kb * be * np.cos(b)
    a12 = kb * (al * np.sinh(a) + be * np.sin(b))
    a21 = dka * np.sinh(a) + dkb * np.sin(b)
    a22 = (kb / ka) * dka * np.cosh(a) - dkb * np.cos(b)
    # a positive normalisation (growth of cosh, and the factor r of the second row) so
    # that the function stays O(1); it does not move the roots
    return float((a11 * a22 - a12 * a21) / (r * np.cosh(a) ** 2 * al * be))


def timoshenko_cantilever_frequencies(
    E: float, G: float, k: float, rho: float, A: float, I: float, L: float, n: int = 3
) -> np.ndarray:
    """The first ``n`` natural frequencies [rad/s] of a uniform Timoshenko cantilever
    (roots of :func:`timoshenko_cantilever_determinant`, bracketed on a fine grid below
    the Euler-Bernoulli frequencies, which bound them from above)."""
    eb = euler_bernoulli_cantilever(E, I, rho, A, L, n + 1)
    grid = np.geomspace(0.2 * eb[0], 1.0001 * eb[n - 1], 4000)
    f = [timoshenko_cantilever_determinant(w, E, G, k, rho, A, I, L) for w in grid]
    roots = []
    for i in range(len(grid) - 1):
        if np.sign(f[i]) != np.sign(f[i + 1]):
            roots.append(
                brentq(
                    timoshenko_cantilever_determinant,
                    grid[i],
                    grid[i + 1],
                    args=(E, G, k, rho, A, I, L),
                    xtol=1e-13,
                    rtol=1e-15,
                )
            )
        if len(roots) == n:
            break
    if len(roots) != n:
        raise RuntimeError(f"found {len(roots)} of {n} roots")
    return np.array(roots)


# --- 3. Static tip deflection ------------------------------------------------------


def timoshenko_tip_deflection(
    P: float, E: float, G: float, k: float, A: float, I: float, L: float
) -> float:
    """Tip deflection [m] of a Timoshenko cantilever under a tip load P [N]:
    :math:`P L^3/(3EI) + P L/(kGA)` (bending + shear; exact for Timoshenko theory)."""
    return P * L**3 / (3.0 * E * I) + P * L / (k * G * A)


def reduced_integration_tip_deflection(
    P: float, E: float, G: float, k: float, A: float, I: float, L: float, n_elements: int
) -> float:
    r"""Tip deflection [m] that the linear (two-node) Timoshenko element with one-point
    shear integration gives on ``n_elements`` equal elements:
    :math:`P L^3/(3EI)\,(1 - 1/(4N^2)) + P L/(kGA)`.

    Derivation: the element's shear force and bending moment are constant, and nodal
    equilibrium makes them equal to the exact shear :math:`P` and the exact moment
    :math:`P(L - x_m)` at the element's mid-point :math:`x_m`. Hence the nodal
    rotations are exact (mid-point rule of a linear moment), the shear strain is exact
    (:math:`P/kGA`), but the deflection increment is the *trapezoidal* rule of the
    quadratic rotation :math:`\theta(x) = P(Lx - x^2/2)/EI`, which is short by
    :math:`h^3 P/(12EI)` per element, i.e. :math:`PL^3/(12EIN^2)` in total. (Reddy's
    "interdependent interpolation" element would be nodally exact; this one is not.)
    """
    return P * L**3 / (3.0 * E * I) * (1.0 - 0.25 / n_elements**2) + P * L / (k * G * A)


# --- 4. GHM modulus -----------------------------------------------------------------


def ghm_modulus(s: complex, kappa: float, alpha: float, omega: float, zeta: float) -> complex:
    r"""GHM shear modulus [Pa] at the Laplace variable ``s`` [1/s] (one mini-oscillator):
    :math:`G(s) = \kappa[1 + \alpha(s^2 + 2\zeta\hat\omega s)/(s^2 + 2\zeta\hat\omega s
    + \hat\omega^2)]` (Golla & Hughes 1985; thesis eq. (20)). ``G(1j*w)`` is the complex
    modulus :math:`G'(\omega) + jG''(\omega)` at the real frequency w."""
    s = complex(s)
    return kappa * (
        1.0 + alpha * (s * s + 2.0 * zeta * omega * s) / (s * s + 2.0 * zeta * omega * s + omega**2)
    )


# --- 5. Sandwich beam ---------------------------------------------------------------


@dataclass(frozen=True)
class Sandwich:
    """A three-layer beam of width ``b`` [m] and length ``L`` [m]: layer 1 base,
    2 viscoelastic core (shear modulus given per call; extensional modulus ``E2``),
    3 constraining layer. ``E*`` [Pa], ``t*`` [m], ``rho*`` [kg/m^3]."""

    b: float
    L: float
    E1: float
    t1: float
    rho1: float
    t2: float
    rho2: float
    E3: float
    t3: float
    rho3: float
    E2: float = 0.0

    @property
    def mass(self) -> float:
        """Mass per unit length m [kg/m] (all three layers)."""
        return self.b * (self.rho1 * self.t1 + self.rho2 * self.t2 + self.rho3 * self.t3)

    @property
    def d(self) -> float:
        """Distance between the face-layer mid-planes, t2 + (t1 + t3)/2 [m] (RKU's H31)."""
        return self.t2 + 0.5 * (self.t1 + self.t3)

    @property
    def D_faces(self) -> float:
        """Sum of the faces' own flexural rigidities E1 I1 + E3 I3 [N m^2] (Mead-Markus D_t)."""
        return self.b * (self.E1 * self.t1**3 + self.E3 * self.t3**3) / 12.0

    @property
    def axial_compliance(self) -> float:
        """1/(E1 A1) + 1/(E3 A3) [1/N]."""
        return 1.0 / (self.E1 * self.b * self.t1) + 1.0 / (self.E3 * self.b * self.t3)

    @property
    def Y(self) -> float:
        """Mead-Markus geometric parameter Y = d^2 / (D_t (1/E1A1 + 1/E3A3)) [-]."""
        return self.d**2 / (self.D_faces * self.axial_compliance)

    def g(self, G2: complex) -> complex:
        """Mead-Markus shear parameter g* = (G2 b / t2)(1/E1A1 + 1/E3A3) [1/m^2]."""
        return G2 * self.b / self.t2 * self.axial_compliance


def rku_flexural_rigidity(p: Sandwich, G2: complex, k: float) -> complex:
    r"""RKU complex flexural rigidity [N m^2] of the sandwich for a flexural wave of
    wavenumber ``k`` [1/m] (wavelength :math:`2\pi/k`), core shear modulus ``G2`` [Pa].

    Ross, Ungar & Kerwin (1959), per unit width, with
    :math:`H_{21} = (t_1 + t_2)/2`, :math:`H_{31} = t_1/2 + t_2 + t_3/2` and the shear
    parameter :math:`g = G_2/(E_3 t_3 t_2 k^2)`:

    .. math::

        \frac{EI}{b} = \frac{E_1t_1^3}{12} + \frac{E_2t_2^3}{12} + \frac{E_3t_3^3}{12}
          - \frac{E_2t_2^2}{12}\frac{H_{31} - D}{1 + g}
          + E_1t_1D^2 + E_2t_2(H_{21} - D)^2 + E_3t_3(H_{31} - D)^2
          - \Big[\frac{E_2t_2}{2}(H_{21} - D) + E_3t_3(H_{31} - D)\Big]
            \frac{H_{31} - D}{1 + g},

        D = \frac{E_2t_2(H_{21} - H_{31}/2) + g(E_2t_2H_{21} + E_3t_3H_{31})}
                 {E_1t_1 + E_2t_2/2 + g(E_1t_1 + E_2t_2 + E_3t_3)} .

    The sandwich loss factor is :math:`\eta = \mathrm{Im}(EI)/\mathrm{Re}(EI)`. RKU
    assume a sinusoidal (simply supported / infinite-beam) deflection shape of
    wavenumber k.
    """
    t1, t2, t3 = p.t1, p.t2, p.t3
    E1, E2, E3 = p.E1, p.E2, p.E3
    H21, H31 = 0.5 * (t1 + t2), 0.5 * t1 + t2 + 0.5 * t3
    g = G2 / (E3 * t3 * t2 * k**2)
    D = (E2 * t2 * (H21 - 0.5 * H31) + g * (E2 * t2 * H21 + E3 * t3 * H31)) / (
        E1 * t1 + 0.5 * E2 * t2 + g * (E1 * t1 + E2 * t2 + E3 * t3)
    )
    ei = (
        E1 * t1**3 / 12
        + E2 * t2**3 / 12
        + E3 * t3**3 / 12
        - E2 * t2**2 / 12 * (H31 - D) / (1 + g)
        + E1 * t1 * D**2
        + E2 * t2 * (H21 - D) ** 2
        + E3 * t3 * (H31 - D) ** 2
        - (0.5 * E2 * t2 * (H21 - D) + E3 * t3 * (H31 - D)) * (H31 - D) / (1 + g)
    )
    return p.b * ei


def mead_markus_flexural_rigidity(p: Sandwich, G2: complex, k: float) -> complex:
    r"""Mead-Markus (1969) complex flexural rigidity [N m^2] for a sinusoidal wave of
    wavenumber ``k`` [1/m]: substituting :math:`w = \sin kx` into their sixth-order
    equation

    .. math::

        w^{(6)} - g^*(1 + Y) w^{(4)} - \frac{m\omega^2}{D_t}(w'' - g^* w) = 0

    gives :math:`m\omega^2 = k^4 D_t [1 + Y g^*/(g^* + k^2)]`. Equal to
    :func:`rku_flexural_rigidity` when the core has no extensional stiffness (E2 = 0).
    """
    g = p.g(G2)
    return p.D_faces * (1.0 + p.Y * g / (g + k**2))


def loss_factor(lam: complex) -> float:
    r"""Loss factor of a mode from its complex eigenvalue ``lam`` [1/s] (Re < 0 < Im):
    :math:`\eta = \mathrm{Im}(-\lambda^2)/\mathrm{Re}(-\lambda^2)`.

    A structure with complex stiffness :math:`K(1 + j\eta)` has free-vibration
    eigenvalues with :math:`-\lambda^2 = \omega^2(1 + j\eta)` exactly, so this is the
    quantity that the RKU/Mead-Markus loss factor :math:`\mathrm{Im}\,EI/\mathrm{Re}\,EI`
    describes; for light damping it equals :math:`2\zeta` of the pole
    (:math:`2\zeta\sqrt{1-\zeta^2}/(1 - 2\zeta^2)` exactly).
    """
    z = -(complex(lam) ** 2)
    return z.imag / z.real


def _pole_from(mw2: complex) -> complex:
    """The eigenvalue lam with -lam^2 = mw2 in the upper half plane (Re lam < 0 when
    Im mw2 > 0)."""
    lam = 1j * np.sqrt(complex(mw2))
    return lam if lam.imag > 0 else -lam


def rku_pole(
    p: Sandwich,
    k: float,
    G: Callable[[complex], complex],
    *,
    evaluate_at: str = "pole",
    rigidity=rku_flexural_rigidity,
    iterations: int = 100,
) -> complex:
    r"""Complex eigenvalue [1/s] of the sandwich mode of wavenumber ``k`` [1/m] from
    :math:`-m\lambda^2 = k^4 EI^*(k, G_2)`.

    ``G`` is the core modulus as a function of the Laplace variable (e.g.
    :func:`ghm_modulus`). ``evaluate_at="pole"`` uses :math:`G_2 = G(\lambda)` (the
    exact eigenvalue of the frequency-dependent model, what a state-space realization
    of G has as its pole); ``"real"`` uses the classical :math:`G_2 = G(j\omega_n)`
    at the real natural frequency :math:`\omega_n^2 = k^4\,\mathrm{Re}(EI^*)/m`. Both
    are solved by fixed-point iteration.
    """
    if evaluate_at not in ("pole", "real"):
        raise ValueError(f"evaluate_at must be 'pole' or 'real', got {evaluate_at!r}")
    lam = _pole_from(k**4 * rigidity(p, G(0.0), k).real / p.mass)
    for _ in range(iterations):
        s = lam if evaluate_at == "pole" else 1j * np.sqrt((-lam * lam).real)
        new = _pole_from(k**4 * rigidity(p, G(s), k) / p.mass)
        if abs(new - lam) < 1e-14 * abs(lam):
            return new
        lam = new
    raise RuntimeError("RKU fixed-point iteration did not converge")


def _mead_markus_system(p: Sandwich, G2: complex, mw2: complex) -> np.ndarray:
    r"""First-order form :math:`Z' = A Z` (:math:`' = d/d\xi`, :math:`x = L\xi`) of the
    Mead-Markus sandwich equations with the axial face displacements kept explicit.

    Energy (per the Mead-Markus assumptions; :math:`c = G_2 b/t_2`, core shear strain
    :math:`\gamma = (u_3 - u_1 + d\,w')/t_2`, core shear force per length
    :math:`S = c\,t_2\gamma = c(u_3 - u_1 + d\,w')`):

    .. math::

        U = \tfrac12\int D_t w''^2 + E_1A_1u_1'^2 + E_3A_3u_3'^2 + \frac{S^2}{c}\,dx,
        \qquad T = \tfrac12\int m\dot w^2 dx,

    whose Euler-Lagrange equations at :math:`-\lambda^2 = \Omega` are
    :math:`E_1A_1u_1'' = -S`, :math:`E_3A_3u_3'' = S`,
    :math:`D_tw'''' - d\,S' - m\Omega w = 0` (eliminating :math:`u_1, u_3` gives the
    sixth-order equation of :func:`mead_markus_flexural_rigidity`), with the natural
    boundary terms :math:`D_tw''\,\delta w'`, :math:`(d\,S - D_tw''')\,\delta w`,
    :math:`E_iA_iu_i'\,\delta u_i`.

    State :math:`Z = [w/L, w', Lw'', L^2w''', u_1/L, u_1', u_3/L, u_3']`.
    """
    L, d, Dt = p.L, p.d, p.D_faces
    c = G2 * p.b / p.t2
    EA1, EA3 = p.E1 * p.b * p.t1, p.E3 * p.b * p.t3
    A = np.zeros((8, 8), dtype=complex)
    A[0, 1] = A[1, 2] = A[2, 3] = A[4, 5] = A[6, 7] = 1.0
    # Z3' = L^3 w'''' = (L^3/Dt) [d c (u3' - u1' + d w'') + m Omega w]
    f = L**3 / Dt
    A[3, 7], A[3, 5], A[3, 2] = f * d * c, -f * d * c, f * d * c * d / L
    A[3, 0] = f * p.mass * mw2 * L
    # S = c (L Z6 - L Z4 + d Z1);  Z5' = -L S / EA1;  Z7' = L S / EA3
    srow = np.zeros(8, dtype=complex)
    srow[6], srow[4], srow[1] = c * L, -c * L, c * d
    A[5] = -L * srow / EA1
    A[7] = L * srow / EA3
    return A


#: Boundary conditions understood by :func:`mead_markus_determinant`.
SUPPORTS = ("clamped-free", "pinned-pinned")


def mead_markus_determinant(
    p: Sandwich, G2: complex, mw2: complex, supports: str = "clamped-free"
) -> complex:
    r"""Frequency determinant of the Mead-Markus sandwich beam at
    :math:`\Omega = -\lambda^2` = ``mw2`` [1/s^2] (:math:`\omega^2` for real frequencies)
    with core modulus ``G2`` [Pa]. The solution is propagated exactly with the matrix
    exponential of :func:`_mead_markus_system`; the determinant is that of the
    boundary conditions at x = L applied to the four free initial values at x = 0.

    ``supports="clamped-free"`` (the FE model's cantilever): at the clamp the base layer
    is fixed, :math:`w = w' = u_1 = 0`, and the constraining layer's end is free,
    :math:`E_3A_3u_3' = 0` (the FE model clamps only the beam's u, w, theta, not the
    VEM shear angle); at the tip no moment :math:`D_tw'' = 0`, no shear force
    :math:`D_tw''' - d\,S = 0`, and free faces :math:`u_1' = u_3' = 0`.

    ``supports="pinned-pinned"`` (a check of this machinery): :math:`w = w'' = 0` and
    :math:`u_3' = 0` at both ends, :math:`u_1 = 0` at x = 0 (axial pin of the base)
    and :math:`u_1' = 0` at x = L (roller). Its modes are exactly sinusoidal,
    :math:`w = \sin(n\pi x/L)`, so its eigenvalues are exactly those of RKU /
    :func:`mead_markus_flexural_rigidity` with :math:`k = n\pi/L`.
    """
    if abs(np.sqrt(p.g(G2))) * p.L > 20.0:
        # the shear-lag solutions grow like exp(sqrt(g) x): beyond this the determinant
        # is lost in round-off (a stiff core is the RKU limit anyway)
        raise ValueError("core too stiff for the transfer-matrix solution: sqrt(|g|) L > 20")
    T = sla.expm(_mead_markus_system(p, G2, mw2))
    e = np.eye(8)
    if supports == "clamped-free":
        L, d = p.L, p.d
        c = G2 * p.b / p.t2
        shear = np.zeros(8, dtype=complex)  # (L^2/D_t)(d S - D_t w''') in the state Z
        shear[3] = -1.0
        f = L**2 * d / p.D_faces
        shear[6], shear[4], shear[1] = f * c * L, -f * c * L, f * c * d
        unknown, R = [2, 3, 5, 6], np.array([e[2], shear, e[5], e[7]])
    elif supports == "pinned-pinned":
        unknown, R = [1, 3, 5, 6], np.array([e[0], e[2], e[5], e[7]])
    else:
        raise ValueError(f"supports must be one of {SUPPORTS}, got {supports!r}")
    return complex(np.linalg.det(R @ T[:, unknown]))


def _secant(
    f: Callable[[complex], complex],
    x0: complex,
    x1: complex,
    tol: float = 1e-13,
    maxiter: int = 100,
) -> complex:
    f0, f1 = f(x0), f(x1)
    for _ in range(maxiter):
        if f1 == f0:
            break
        x2 = x1 - f1 * (x1 - x0) / (f1 - f0)
        if abs(x2 - x1) < tol * abs(x2):
            return x2
        x0, f0, x1, f1 = x1, f1, x2, f(x2)
    raise RuntimeError("secant iteration did not converge")


def mead_markus_pole(
    p: Sandwich,
    G: Callable[[complex], complex],
    lam0: complex,
    *,
    supports: str = "clamped-free",
    evaluate_at: str = "pole",
    iterations: int = 100,
) -> complex:
    r"""Complex eigenvalue [1/s] of the Mead-Markus sandwich beam (``supports`` as in
    :func:`mead_markus_determinant`) nearest the starting guess ``lam0`` (e.g.
    :func:`rku_pole`): a root of the determinant in :math:`\Omega = -\lambda^2`.

    ``G`` and ``evaluate_at`` as in :func:`rku_pole`: the core modulus is
    :math:`G(\lambda)` (``"pole"``) or :math:`G(j\omega_n)` with
    :math:`\omega_n^2 = \mathrm{Re}\,\Omega` (``"real"``), by fixed-point iteration
    around a secant solve in :math:`\Omega`.
    """
    if evaluate_at not in ("pole", "real"):
        raise ValueError(f"evaluate_at must be 'pole' or 'real', got {evaluate_at!r}")
    lam = complex(lam0)
    for _ in range(iterations):
        s = lam if evaluate_at == "pole" else 1j * np.sqrt((-lam * lam).real)
        G2 = G(s)
        om = -lam * lam
        om = _secant(
            lambda z, G2=G2: mead_markus_determinant(p, G2, z, supports), om, om * (1 + 1e-4)
        )
        new = _pole_from(om)
        if abs(new - lam) < 1e-13 * abs(lam):
            return new
        lam = new
    raise RuntimeError("Mead-Markus fixed-point iteration did not converge")
