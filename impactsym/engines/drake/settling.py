r"""When a loaded ``time_step`` contact provably never ends: the rules by which the step
loops of :mod:`impactsym.engines.drake.stepping` declare it sticking early
(:func:`stuck_early`), each a proof that the full loop would step it to its limit
(:data:`~impactsym.engines.drake.stepping.MAX_STEPS`, ``MAX_STEPS`` below). The loops
check them every 64 updates.

*A settled contact* (``"tamsi"``/``"similar"``/``"lagged"`` under gravity) is declared
sticking as soon as it provably never ends, instead of after ``MAX_STEPS`` updates (a
heavily damped loaded contact creeps to rest without turning back: 2·10^6 updates, a
minute per call). While the update carries an impulse, the discrete energy :math:`E = m
u^2/2 + k x^2/2 - m g x` falls: with :math:`x' = x + h u'`, :math:`E' - E = -h k d x'
u'^2 - m (u' - u)^2/2 - k h^2 u'^2/2 \le 0`. Let the well be :math:`W = (m g)^2/(2k)`
and :math:`E \le -c W` (``c > 0``; applied from ``c > 0.01``). Allowing rounding to give
back :math:`10^{-6} W` (far more than ``MAX_STEPS`` updates can), every later state has
:math:`|x - x_e| \le \rho x_e` (:math:`x_e = m g/k`) and :math:`|u| \le \rho g T`
(:math:`T = \sqrt{m/k}`, :math:`\rho = \sqrt{1 - c + 10^{-6}}`). There the impulse
cannot vanish: ``u* <= -x/h`` would need :math:`E \ge k x^2/2 \ge 0`, and ``u* <= -1/d``
is excluded by :math:`d \rho g T < 1`; it stays above the ``1e-12 m v`` floor where
:math:`h g (1 - \rho)(1 - d \rho g T) > 2\cdot 10^{-12} v`. So the contact never ends,
as the full loop would find. The rule is applied only where the largest penetration and
force so far already exceed their bounds :math:`x_e(1 + \rho)` and :math:`m g (1 +
\rho)(1 + d \rho g T)` (then ``max_penetration`` and ``peak_accel`` are those of the
full loop; ``steps`` of a sticking contact counts the updates until the verdict). A
caller that does not read the peaks of sticking contacts (``stuck_peaks=False``: the
phase means of the designs by contact time, and the step table's, which leaves sticking
nodes and designs by largest overlap to the iteration) drops that condition: a contact
creeping up to its rest from below is then decided as soon, its peaks being those until
the verdict.

*Creeping up to rest* (``"tamsi"``/``"similar"``/``"lagged"`` under gravity): a heavily
damped loaded contact that approaches its rest :math:`x_e` from below never reaches
the energy rule's peak bounds; stepped, rounding stalls it after about 30 of its slow
time constants :math:`m g d/k` (``h u'`` under half an ulp of ``x``): 10^5-10^6 updates
for soft, heavily damped contacts at small steps (``k = 10^3`` N/m, ``m = 1`` kg,
``d = 500`` s/m, ``h = 10^{-4}`` s: 1.2·10^6 updates; up to ``MAX_STEPS``, about
two minutes a call). With :math:`\delta = x_e - x > 0`,
:math:`\eta = h u \ge 0`, :math:`a = h^2 k/m` and the update's damping term
:math:`\beta' = h d g\, x'/x_e`, the update reads
:math:`\eta' (1 + a + \beta') = \eta + a \delta`, :math:`\delta' = \delta - \eta'`.
While :math:`\delta` falls, :math:`\beta' \ge B = h d g\, x/x_e`; if
:math:`\eta \le \mu \delta` with :math:`\mu^2 - B \mu + a \le 0` (real roots need
:math:`B^2 > 4a`, the discrete over-damping), then :math:`\eta'(1 + \mu) \le \mu
\delta` (expand), i.e. :math:`\eta' \le \mu \delta'` with :math:`\delta' > 0`: the cone
is invariant, ``x`` rises for ever towards :math:`x_e` (geometrically, since
:math:`\eta' \ge a\delta/(1 + a + h d g)`), the contact and its impulse
(:math:`\ge h k x`) never end. Every later force :math:`k x' (1 + d u')` is at most
:math:`m g \max_{0 < y \le \delta/x_e} (1 - y)(1 + c y)`, :math:`c = d \mu x_e/h`. Where
the state lies in such a cone (``mu`` at least the current ratio) and the force so far
already exceeds that bound (margins of ``1e-9``), the contact sticks, its force has
peaked and its largest penetration is :math:`\max(x_{\max}, x_e)`: the limit of the
creep, which the full loop approaches from below and stalls at by rounding, about
:math:`(a + h d g)/(2a)` ulps short (5e-15 relative at ``k = 10^4`` N/m, ``m = 1`` kg,
``d = 50`` s/m, ``h = 10^{-3}`` s; rarely an ulp or two above), or stops at
``MAX_STEPS`` short of it (where its slow time constant exceeds ~6·10^4 updates).
Checked whatever ``stuck_peaks``.

*A contact at rest* (any approximation under gravity, ``"sap"`` included) is declared
sticking once an update gives back its state bit for bit (``u' = u`` and
``x + h u' = x``): the loop is deterministic, so every later update repeats it, the
contact never ends and its peaks are final, those of the full loop.

All quantities are SI. Internal to :mod:`impactsym.engines.drake`.
"""

from __future__ import annotations

import numpy as np

__all__ = ["IMPULSE_FLOOR", "stuck_early"]

#: Impulses below this times ``m v`` count as zero (the end test of the step loops).
IMPULSE_FLOOR = 1e-12
_DRIFT = 1e-6  # energy (in wells) that rounding may give back, in the rule


def stuck_early(
    going, x, u, new, k, d, m, g, h, v, x_max, peak, stuck_peaks, *, hunt_crossley=True
):
    """``(stuck, x_max)``: the contacts among ``going`` (state ``x, u``, next velocity
    ``new``) that the rules (module docstring) declare sticking now, and the
    largest penetrations with those creeping up to rest raised to it (``m g / k``).
    At rest to the last bit under any update; settled or creeping only under the
    Hunt–Crossley update (``hunt_crossley``). Shared by
    :func:`~impactsym.engines.drake.stepping.step_contact` and
    :func:`~impactsym.engines.drake.stepping.contact_ends`, so that their verdicts stay
    the same."""
    stuck = going & (new == u) & (x + h * new == x)  # the update gives back the state
    if not hunt_crossley:
        return stuck, x_max
    stuck |= going & _settled(x, u, k, d, m, g, h, v, x_max, peak, stuck_peaks)
    creep = going & _creeping(x, u, k, d, m, g, h, v, peak)
    return stuck | creep, np.where(creep, np.maximum(x_max, m * g / k), x_max)


def _settled(x, u, k, d, m, g, h, v, x_max, peak, stuck_peaks):
    """Where a contact under gravity provably never ends (module docstring: its energy
    lies deep enough in the well) and, if ``stuck_peaks``, its penetration and force have
    already peaked."""
    with np.errstate(all="ignore"):
        well = (m * g) ** 2 / (2.0 * k)
        c = -(0.5 * m * u * u + 0.5 * k * x * x - m * g * x) / well
        rho = np.sqrt(np.maximum(1.0 - c, 0.0) + _DRIFT)
        speed = d * rho * g * np.sqrt(m / k)  # d times the largest |u| from here on
        x_e = m * g / k
        never_ends = (
            (g > 0)
            & (c > 1e-2)
            & (speed < 1.0)
            & (h * g * (1.0 - rho) * (1.0 - speed) > 2.0 * IMPULSE_FLOOR * v)
        )
        if not stuck_peaks:
            return never_ends
        peaked = (x_max >= x_e * (1.0 + rho)) & (peak >= m * g * (1.0 + rho) * (1.0 + speed))
        return never_ends & peaked


def _creeping(x, u, k, d, m, g, h, v, peak):
    """Where a ``"tamsi"``/``"similar"``/``"lagged"`` contact under gravity provably
    creeps up to its rest ``x_e = m g / k`` from below for ever, and its force has
    already peaked (module docstring, "creeping up to rest"). Margins of ``1e-9``
    relative cover rounding, and of ``1e-12 b^2`` in the discriminant (its cancellation
    near the critical damping)."""
    with np.errstate(all="ignore"):
        x_e = m * g / k
        gap = x_e - x  # delta > 0: below the rest
        a = h * h * k / m
        b = h * d * g * x / x_e  # the least damping term of every later update
        disc = b * b - 4.0 * a
        root = np.sqrt(np.maximum(disc, 0.0))
        mu_hi, mu_lo = 0.5 * (b + root), 2.0 * a / (b + root)  # mu^2 - b mu + a = 0
        ratio = h * u / gap
        mu = np.maximum(ratio, mu_lo) * (1.0 + 1e-9)  # h u' <= mu (x_e - x') from here on
        # the largest later force over m g: (1 - y)(1 + c y), y = (x_e - x')/x_e <= gap/x_e
        c = d * mu * x_e / h
        y = np.clip((c - 1.0) / (2.0 * c), 0.0, gap / x_e)
        force = np.maximum(1.0, (1.0 - y) * (1.0 + c * y)) * (1.0 + 1e-9)
        return (
            (g > 0)
            & (x >= 0.0)
            & (gap > 0.0)
            & (u >= 0.0)
            & (disc > 1e-12 * b * b)
            & (ratio * (1.0 + 1e-9) <= mu_hi * (1.0 - 1e-9))
            & (h * g * x / x_e > 2.0 * IMPULSE_FLOOR * v)
            & (peak >= m * g * force)
        )
