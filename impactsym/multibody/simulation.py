"""Full nonlinear simulation of penalty contacts in two example multibody systems.

The reference for :mod:`impactsym.multibody`'s reduced oscillator, usable without
SciPy: two planar systems whose effective contact mass differs clearly from every
body mass (a falling bar, a double pendulum striking a wall), a vectorized fixed-step
RK4 with event location (NumPy only; the tests check it against
``scipy.integrate.solve_ivp``), and the sweeps that compare reduced and full models
(``docs/physics.md``, section 3). The systems live in :mod:`impactsym.multibody.examples`
and are importable from here too. Horizons ``t_max`` are normalized, in units of
``1 / omega`` with ``omega = sqrt(k / m~)``; ``tau_max`` is their former name.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import sympy as sp

from impactsym.multibody.examples import MultibodyExample
from impactsym.multibody.examples import double_pendulum as double_pendulum
from impactsym.multibody.examples import examples as examples
from impactsym.multibody.examples import falling_bar as falling_bar
from impactsym.multibody.oscillator import ReducedContact
from impactsym.multibody.reduction import PROJECTIONS
from impactsym.numeric.codegen import lambdify
from impactsym.numeric.roots import bracketed_illinois
from impactsym.records import ArrayRecord
from impactsym.validation import as_sympy, check_condition, check_count, real_array, renamed


# ---------------------------------------------------------------------------------
# full nonlinear simulation (NumPy)
# ---------------------------------------------------------------------------------
class _Equations:
    """Vectorized ``M(q)``, ``F(q, u)``, ``g(q)`` and ``n(q)`` of an example."""

    def __init__(self, example: MultibodyExample) -> None:
        args = [*example.q, *example.qd]
        n = self.n = len(example.q)

        def compile_(expr: sp.Expr, name: str) -> Callable[..., np.ndarray] | float:
            expr = as_sympy(name, expr)
            return float(expr) if expr.is_number else lambdify(args, expr, name=name)

        self._M = [compile_(example.M[i, j], f"M{i}{j}") for i in range(n) for j in range(n)]
        self._F = [compile_(example.F[i], f"F{i}") for i in range(n)]
        self._n = [compile_(example.g.diff(s), f"n{i}") for i, s in enumerate(example.q)]
        self._g = compile_(example.g, "g")

    def parts(self, y: np.ndarray) -> tuple[np.ndarray, ...]:
        """``M`` (B, n, n), ``F`` (B, n), ``normal`` (B, n), ``g`` (B,) at states ``y`` (2n, B)."""
        args, size = list(y), y.shape[1]

        def value(f: Callable[..., np.ndarray] | float) -> np.ndarray:
            return np.full(size, f) if isinstance(f, float) else f(*args)

        M = np.stack([value(f) for f in self._M], axis=-1).reshape(size, self.n, self.n)
        F = np.stack([value(f) for f in self._F], axis=-1)
        normal = np.stack([value(f) for f in self._n], axis=-1)
        return M, F, normal, value(self._g)

    def rhs(self, y: np.ndarray, k: np.ndarray, d: np.ndarray) -> np.ndarray:
        """Persistent-contact right-hand side ``(q', u')`` for states ``y`` (2n, B)."""
        M, F, normal, g = self.parts(y)
        u = y[self.n :].T
        lam = -(k * g + d * np.einsum("bi,bi->b", normal, u))
        accel = np.linalg.solve(M, (F + normal * lam[:, None])[..., None])[..., 0]
        return np.concatenate([y[self.n :], accel.T])

    def normal_velocity(self, y: np.ndarray) -> np.ndarray:
        """Signed normal velocity ``g' = n(q)^T q'`` per sample (positive: approaching)."""
        _, _, normal, _ = self.parts(y)
        return np.einsum("bi,bi->b", normal, y[self.n :].T)

    def condition(self, y: np.ndarray, k: np.ndarray, d: np.ndarray, force: np.ndarray):
        """Penetration (position) or penalty force ``k g + d g'`` (force), per sample."""
        _, _, normal, g = self.parts(y)
        gdot = np.einsum("bi,bi->b", normal, y[self.n :].T)
        return np.where(force, k * g + d * gdot, g)


def _rk4(eq: _Equations, y: np.ndarray, h: np.ndarray, k: np.ndarray, d: np.ndarray):
    k1 = eq.rhs(y, k, d)
    k2 = eq.rhs(y + 0.5 * h * k1, k, d)
    k3 = eq.rhs(y + 0.5 * h * k2, k, d)
    k4 = eq.rhs(y + h * k3, k, d)
    return y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


@dataclass(frozen=True, eq=False)
class SimulatedContact(ArrayRecord):
    """Result of :func:`simulate_contact`: contact time and restitution per case."""

    contact_time: np.ndarray  #: contact time (``inf``: still in contact at the horizon)
    restitution: np.ndarray  #: ``-g'(t_c) / g'(0)`` (``0.0`` when still in contact)

    @property
    def sticks(self) -> np.ndarray:
        """``True`` where the contact lasts beyond the horizon (``contact_time`` is ``inf``)."""
        return ~np.isfinite(self.contact_time)


def simulate_contact(
    example: MultibodyExample,
    k: Any,
    d: Any,
    speed: Any,
    *,
    condition: str | Sequence[str],
    t_max: float | None = None,
    steps: int = 50,
    tau_max: float | None = None,
) -> SimulatedContact:
    r"""Contact time and restitution of the full nonlinear penalty model.

    Integrates the persistent-contact equations
    ``M(q) q'' = F(q, q') - n(q) (k g + d g')`` from the impact state with a fixed-step
    RK4 (``steps`` per time unit ``1 / omega``, ``omega = sqrt(k / m~)``) and locates the
    first crossing of the contact condition (``g = 0`` or ``k g + d g' = 0``) by the
    Illinois method on the partial step. ``k``, ``d``, ``speed`` and ``condition``
    broadcast; all cases are integrated together.

    .. math::

        t_c = \min\{t > 0 : c(t) = 0\}, \qquad c = g \ \text{or}\ k g + d \dot g,
        \qquad e = -\dot g(t_c) / \dot g(0),

    and ``t_c = inf``, ``e = 0`` when there is no crossing before ``t_max / omega``
    (``t_max`` is a normalized horizon, in units of ``1 / omega``; ``tau_max`` is its
    former name, still accepted). The reference for the reduction
    (``docs/physics.md``, section 3); fixed steps in ``1 / omega`` keep all cases of a
    sweep in one vectorized loop.

    Without gravity and damping the bar bounces off after about half a period of the
    reduced oscillator, ``pi / omega``, with ``e`` about 1:

    >>> bar = falling_bar(gravity=0.0, drag=0.0, rotational_drag=0.0)
    >>> sim = simulate_contact(bar, 1e4, 0.0, 0.5, condition="position")
    >>> omega = np.sqrt(1e4 / bar.reduce().m_eff)
    >>> round(float(sim.contact_time * omega), 2), round(float(sim.restitution), 2)
    (3.13, 1.01)
    """
    t_max = renamed("t_max", t_max, "tau_max", tau_max, 40.0)
    k_arr, _ = real_array("k", k, lower=0.0, strict=True)
    d_arr, _ = real_array("d", d, lower=0.0)
    v_arr, _ = real_array("speed", speed, lower=0.0, strict=True)
    steps, t_max = _step_budget(steps, t_max)
    if isinstance(condition, str):
        check_condition(condition)
    else:
        for c in np.asarray(condition, dtype=object).ravel():
            check_condition(c)
    cond = np.asarray(condition)
    shape = np.broadcast_shapes(k_arr.shape, d_arr.shape, v_arr.shape, cond.shape)
    k_b, d_b, v_b = (np.broadcast_to(a, shape).ravel() for a in (k_arr, d_arr, v_arr))
    force = np.broadcast_to(cond == "force", shape).ravel()
    eq = _Equations(example)
    h = 1.0 / (steps * np.sqrt(k_b / example.reduce().m_eff))
    y = np.array(
        [np.full(k_b.size, float(q)) for q in example.q0] + [v_b * c for c in example.direction]
    )
    v0 = eq.normal_velocity(y)
    t_c, e = np.full(k_b.size, np.inf), np.zeros(k_b.size)
    active = np.arange(k_b.size)
    c_old = eq.condition(y, k_b, d_b, force)
    for step in range(int(np.ceil(t_max * steps))):
        if active.size == 0:
            break
        ka, da, ha, fa = k_b[active], d_b[active], h[active], force[active]
        y_old = y[:, active]
        y_new = _rk4(eq, y_old, ha, ka, da)
        c_new = eq.condition(y_new, ka, da, fa)
        crossed = (c_old[active] > 0) & (c_new <= 0)
        if crossed.any():
            sel = np.flatnonzero(crossed)
            args = (ha[sel], ka[sel], da[sel], fa[sel])
            theta, y_c = _locate(eq, y_old[:, sel], *args)
            t_c[active[sel]] = (step + theta) * ha[sel]
            e[active[sel]] = -eq.normal_velocity(y_c) / v0[active[sel]]
        y[:, active] = y_new
        c_old[active] = c_new
        active = active[~crossed]
    return SimulatedContact(t_c.reshape(shape), e.reshape(shape))


#: The most RK4 steps one simulated contact may take (``t_max * steps``): about a
#: minute of work for a single case; a larger budget is refused by name.
MAX_STEPS = 10**6


def _step_budget(steps: object, t_max: object) -> tuple[int, float]:
    """``steps`` per time unit and the horizon ``t_max``, checked against :data:`MAX_STEPS`."""
    steps = check_count("steps", steps, upper=MAX_STEPS)
    horizon, _ = real_array("t_max", t_max, lower=0.0, strict=True)
    if horizon.ndim:
        raise TypeError(f"t_max must be one number, got an array of shape {horizon.shape}")
    t_max = float(horizon)
    if t_max * steps > MAX_STEPS:
        raise ValueError(
            f"t_max * steps = {t_max:g} * {steps} asks for more than {MAX_STEPS} RK4 steps "
            "per case; lower t_max (in units of 1 / omega) or steps"
        )
    return steps, t_max


def _locate(eq, y0, h, k, d, force) -> tuple[np.ndarray, np.ndarray]:
    """Fraction ``theta`` of the step where the condition crosses zero (Illinois method),
    and the state there."""

    def rising(theta: np.ndarray, i: np.ndarray) -> np.ndarray:  # > 0 past the crossing
        y = _rk4(eq, y0[:, i], theta * h[i], k[i], d[i])
        return -eq.condition(y, k[i], d[i], force[i])

    theta = bracketed_illinois(rising, np.zeros_like(h), np.ones_like(h), atol=1e-13)
    return theta, _rk4(eq, y0, theta * h, k, d)


# ---------------------------------------------------------------------------------
# agreement of the reduced model with the full simulation
# ---------------------------------------------------------------------------------
def reduce_at_speeds(
    example: MultibodyExample, speeds: Any, *, projection: str = "impulse"
) -> ReducedContact:
    """The reduction for many impact speeds at once (``load``, ``v0``, ... as arrays).

    The reduction is derived once with a symbolic speed and evaluated on ``speeds``;
    ``k = 1``, ``d = 0`` are placeholders for
    :meth:`~impactsym.multibody.reduction.ReducedContact.with_penalty`.

    >>> r = reduce_at_speeds(falling_bar(), [0.1, 1.0])
    >>> r.v0.tolist()
    [0.1, 1.0]
    """
    s = sp.Symbol("s", positive=True)
    r = example.reduce(1.0, 0.0, s, projection=projection, simplify=False)
    speeds_arr, _ = real_array("speeds", speeds, lower=0.0, strict=True)
    values = {}
    for name in ("m_eff", "delta_d", "delta_c", "load", "v0"):
        expr = as_sympy(name, getattr(r, name))
        values[name] = np.array(lambdify([s], expr, name=name)(speeds_arr))
    if np.any(values["v0"] <= 0):
        raise ValueError("the impact direction gives no approach speed (v0 <= 0)")
    return replace(
        r,
        m_eff=float(values["m_eff"].flat[0]),
        delta_d=values["delta_d"],
        delta_c=values["delta_c"],
        load=values["load"],
        v0=values["v0"],
    )


@dataclass(frozen=True, eq=False)
class Agreement(ArrayRecord):
    """Reduced against full model over a sweep of ``(k, d, speed)`` for one example.

    ``m_eff`` is the effective mass, ``t_full[condition]`` the simulated contact times
    (``inf``: still in contact at ``t_max / sqrt(k / m_eff)``),
    ``t_reduced[(projection, condition)]`` the predictions,
    ``D[projection]``, ``f[projection]``, ``omega0[projection]`` the section-2
    parameters of the reduced oscillator.
    """

    example: str
    m_eff: float
    k: np.ndarray
    d: np.ndarray
    speed: np.ndarray
    t_max: float
    t_full: dict[str, np.ndarray]
    t_reduced: dict[tuple[str, str], np.ndarray]
    D: dict[str, np.ndarray]
    f: dict[str, np.ndarray]
    omega0: dict[str, np.ndarray]

    @property
    def tau_max(self) -> float:
        """Former name of ``t_max``, the normalized simulation horizon."""
        return self.t_max

    def summary(self) -> list[dict[str, Any]]:
        """Hit rate of the stick/release verdict and contact-time errors, per case."""
        rows = []
        for (projection, condition), t_red in self.t_reduced.items():
            t_full = self.t_full[condition]
            stick_full, stick_red = ~np.isfinite(t_full), ~np.isfinite(t_red)
            both = ~stick_full & ~stick_red
            err = np.abs(t_red[both] / t_full[both] - 1)
            rows.append(
                {
                    "system": self.example,
                    "projection": projection,
                    "condition": condition,
                    "cases": int(t_full.size),
                    "full_sticks": int(stick_full.sum()),
                    "verdict_hits": int((stick_full == stick_red).sum()),
                    "hit_rate": float((stick_full == stick_red).mean()),
                    "both_release": int(both.sum()),
                    "median_rel_error": float(np.median(err)) if err.size else float("nan"),
                    "p90_rel_error": float(np.quantile(err, 0.9)) if err.size else float("nan"),
                    "max_rel_error": float(err.max()) if err.size else float("nan"),
                }
            )
        return rows

    def rows(self) -> list[dict[str, Any]]:
        """One row per sweep point, condition and projection (for CSV)."""
        out = []
        for (projection, condition), t_red in self.t_reduced.items():
            for i in range(self.k.size):
                out.append(
                    {
                        "system": self.example,
                        "projection": projection,
                        "condition": condition,
                        "k": self.k[i],
                        "d": self.d[i],
                        "speed": self.speed[i],
                        "D": self.D[projection][i],
                        "f": self.f[projection][i],
                        "omega0": self.omega0[projection][i],
                        "t_full": self.t_full[condition][i],
                        "t_reduced": t_red[i],
                    }
                )
        return out


def agreement_sweep(
    example: MultibodyExample,
    *,
    omegas: Sequence[float] = (150.0, 400.0, 1000.0),
    dampings: Sequence[float] = tuple(np.geomspace(0.05, 2.0, 7)),
    forces: Sequence[float] = tuple(np.geomspace(0.05, 5.0, 7)),
    max_speed: float = 2.0,
    t_max: float | None = None,
    steps: int = 50,
    tau_max: float | None = None,
) -> Agreement:
    r"""Sweep ``(k, d, speed)`` and compare the reduced model with the full simulation.

    The grid is set by targets for the reduced oscillator: angular frequencies
    ``omegas`` give ``k = m~ omega^2``, damping ratios ``dampings`` give
    ``d = 2 D m~ omega``, and normalized loads ``forces`` give the impact speed
    ``v = m~ a / (d f)`` (``a`` the normal acceleration of the free system at rest).
    The reduced ``D``, ``f`` then differ from the targets by the system's own forces.

    .. math:: k = \tilde m \omega^2, \quad d = 2 D \tilde m \omega, \quad
              v = \frac{\tilde m a}{d f}

    Grid points with ``v > max_speed`` (in the units of the example's speeds) are left
    out: the reduction is an impact model, not one for large configuration changes.
    ``t_max`` is the normalized horizon of :func:`simulate_contact` (former name
    ``tau_max``, still accepted).

    >>> a = agreement_sweep(double_pendulum(), omegas=(1000.0,), dampings=(0.1,),
    ...                     forces=(0.5,), steps=20)
    >>> [(row["projection"], row["condition"], row["hit_rate"]) for row in a.summary()][:2]
    [('impulse', 'position', 1.0), ('impulse', 'force', 1.0)]
    """
    t_max = renamed("t_max", t_max, "tau_max", tau_max, 40.0)
    m_eff = example.reduce().m_eff
    rest = reduce_at_speeds(example, [1e-9]).load / m_eff
    omega, D, f = np.meshgrid(omegas, dampings, forces, indexing="ij")
    k = (m_eff * omega**2).ravel()
    d = (2 * D * m_eff * omega).ravel()
    speed = m_eff * float(rest[0]) / (d * f.ravel())
    keep = speed <= max_speed
    k, d, speed = k[keep], d[keep], speed[keep]
    conditions = ("position", "force")
    cond = np.repeat(np.array(conditions), k.size)
    t_all = simulate_contact(
        example,
        np.tile(k, 2),
        np.tile(d, 2),
        np.tile(speed, 2),
        condition=cond,
        t_max=t_max,
        steps=steps,
    ).contact_time
    t_full = {c: t_all[i * k.size : (i + 1) * k.size] for i, c in enumerate(conditions)}
    t_reduced, D_out, f_out, w_out = {}, {}, {}, {}
    for projection in PROJECTIONS:
        red = reduce_at_speeds(example, speed, projection=projection).with_penalty(k, d)
        D_out[projection], f_out[projection] = red.D, red.f
        w_out[projection] = red.omega0
        for c in conditions:
            t_red = np.asarray(red.contact_time(c), dtype=float)
            # beyond the simulated horizon the full model cannot tell release from sticking
            horizon = t_max / np.sqrt(k / m_eff)  # as in simulate_contact
            t_reduced[(projection, c)] = np.where(t_red > horizon, np.inf, t_red)
    return Agreement(
        example.name, m_eff, k, d, speed, t_max, t_full, t_reduced, D_out, f_out, w_out
    )


def convergence_study(
    example: MultibodyExample,
    omegas: Sequence[float],
    *,
    damping: float = 0.15,
    force: float = 0.3,
    condition: str,
    steps: int = 50,
) -> dict[str, np.ndarray]:
    """Relative contact-time error of the reduced model as the contact stiffens.

    For each ``omega`` the penalty is ``k = m~ omega^2``, ``d = 2 D m~ omega`` and the
    speed is chosen for the target ``f`` as in :func:`agreement_sweep` (so ``v`` falls as
    ``1/omega``). Returns ``{"omega": ..., "impulse": ..., "normal": ...}`` with the
    signed relative errors ``t_reduced / t_full - 1``.

    >>> conv = convergence_study(double_pendulum(), [1000.0], steps=20, condition="position")
    >>> bool(abs(conv["impulse"][0]) < abs(conv["normal"][0]) < 1e-3)
    True
    """
    check_condition(condition)
    omegas_arr, _ = real_array("omegas", omegas, lower=0.0, strict=True)
    if omegas_arr.ndim != 1 or omegas_arr.size == 0:
        raise ValueError(f"omegas must be a non-empty 1-d sequence, got shape {omegas_arr.shape}")
    check_count("steps", steps, upper=MAX_STEPS)
    m_eff = example.reduce().m_eff
    rest = float(reduce_at_speeds(example, [1e-9]).load[0]) / m_eff
    k = m_eff * omegas_arr**2
    d = 2 * damping * m_eff * omegas_arr
    speed = m_eff * rest / (d * force)
    t_full = simulate_contact(example, k, d, speed, condition=condition, steps=steps).contact_time
    out = {"omega": omegas_arr}
    for projection in PROJECTIONS:
        red = reduce_at_speeds(example, speed, projection=projection).with_penalty(k, d)
        out[projection] = np.asarray(red.contact_time(condition), dtype=float) / t_full - 1
    return out
