r"""One impact of a contact law in the law's own dimensionless numbers (damping, ``f``).

The section-2 questions of :mod:`~impactsym.contact.lawstick`,
:mod:`~impactsym.contact.lawgrid` and :mod:`~impactsym.contact.lawbounce` are asked in the
plane of a law's damping number :math:`\delta` (``D``, ``s``, ``alpha`` or ``beta``) and
pressing number ``f`` of :mod:`impactsym.contact.laws`. This module evaluates one impact
there, on flat arrays:

* ``"linear"``: the paper's numbers ``(D, f)`` with :math:`b = 2Df`, by the exact closed
  forms of :func:`~impactsym.contact.api.contact_time` and
  :func:`~impactsym.contact.api.restitution` (so its verdicts are those of
  :func:`~impactsym.contact.api.stick_boundary`);
* every other law: :func:`~impactsym.contact.nonlinear.normalized_impact` with
  :math:`b = f` (closed forms where they hold, else the order-8 integration whose
  sticking verdict is decided by energy, never by a time limit).
"""

from __future__ import annotations

import numpy as np

from impactsym.contact.api import contact_time, restitution
from impactsym.contact.laws import check_law
from impactsym.contact.nonlinear import check_law_condition, clipped_linear, normalized_impact
from impactsym.validation import broadcast, real_array

ArrayLike = float | np.ndarray


def exponent_in_use(law: str, exponent: np.ndarray) -> np.ndarray:
    """The spring exponent the law uses: 1 (linear), 3/2 (viscoelastic), else ``exponent``."""
    fixed = {"linear": 1.0, "viscoelastic": 1.5}.get(law)
    if fixed is None:
        return np.asarray(exponent, dtype=float)
    return np.full(np.shape(exponent), fixed)


def law_inputs(
    law: str, *, condition: str, exponent: object, **arrays: object
) -> tuple[list[np.ndarray], np.ndarray, tuple[int, ...], bool]:
    """Check ``law``, ``condition``, non-negative real ``arrays`` and ``exponent >= 1``;
    return the arrays broadcast and flattened, the exponent in use (flat), the common
    shape and whether all inputs were scalars."""
    check_law(law)
    check_law_condition(condition)
    checked = {name: real_array(name, value, lower=0.0) for name, value in arrays.items()}
    checked["exponent"] = real_array("exponent", exponent, lower=1.0)
    shape = broadcast(**{name: a for name, (a, _) in checked.items()})
    flat = [np.broadcast_to(a, shape).ravel() for a, _ in checked.values()]
    scalar = all(s for _, s in checked.values())
    return flat[:-1], exponent_in_use(law, flat[-1]), shape, scalar


def law_impact(
    law: str, delta: np.ndarray, f: np.ndarray, q: np.ndarray, *, condition: str
) -> tuple[np.ndarray, np.ndarray]:
    """Normalized contact time (``inf``: sticks) and restitution (``0`` when sticking) of
    one impact per element of the flat arrays (damping number, pressing number, exponent
    in use)."""
    delta, f, q = (np.asarray(a, dtype=float) for a in (delta, f, q))
    if delta.size == 0:
        return np.empty(0), np.empty(0)
    if law == "linear":
        released = "force" if condition == "clipped" else condition
        tau_c = np.asarray(contact_time(delta, f, condition=released), dtype=float)
        e = np.asarray(restitution(delta, f, condition=released), dtype=float)
        if condition == "clipped":
            tau_c, e = clipped_linear(tau_c, e, delta, 2.0 * delta * f)
        return tau_c.reshape(delta.shape), e.reshape(delta.shape)
    tau_c, e, _, _ = normalized_impact(law, delta, f, q, condition=condition)
    return tau_c, e
