r"""PyBullet's pair rules: how two bodies' ``contactStiffness``/``contactDamping`` combine.

``btManifoldResult`` gives every contact point of a pair (when either body has its own
stiffness and damping, ``CF_HAS_CONTACT_STIFFNESS_DAMPING``):

.. math:: k = \frac{1}{1/k_A + 1/k_B}, \qquad c = c_A + c_B,

with the defaults of ``btCollisionObject``: ``contactStiffness = BT_LARGE_FLOAT``
(``1e18``: rigid) and ``contactDamping = 0.1`` (N s/m). A body whose stiffness and
damping are never set still brings its ``0.1`` to the sum: the plane of a sphere-on-plane
scene adds ``0.1`` N s/m to the ball's damping. ``changeDynamics`` sets both values of a
body together (``contactStiffness=``, ``contactDamping=``). SI units.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from impactsym.validation import finish, real_array

__all__ = ["DEFAULT_DAMPING", "DEFAULT_STIFFNESS", "combine_pair", "split_pair"]

#: ``btCollisionObject``'s ``m_contactDamping`` unless ``changeDynamics`` sets it (N s/m)
DEFAULT_DAMPING = 0.1
#: ``btCollisionObject``'s ``m_contactStiffness`` unless set (``BT_LARGE_FLOAT``, N/m)
DEFAULT_STIFFNESS = 1e18


def combine_pair(
    *, stiffness: Any, damping: Any, other_stiffness: Any = np.inf, other_damping: Any = 0.1
) -> tuple[float | np.ndarray, float | np.ndarray]:
    """The pair's ``(k, c)``: stiffness in series, damping summed.

    ``other_stiffness=inf`` (default) stands for a body left at PyBullet's default
    ``1e18`` (the series sum differs by ``k / 1e18``, below rounding for any usable ``k``).

    >>> combine_pair(stiffness=1e4, damping=40.0)
    (10000.0, 40.1)
    >>> combine_pair(stiffness=1e4, damping=20.0, other_stiffness=1e4, other_damping=20.0)
    (5000.0, 40.0)
    """
    k, s1 = real_array("stiffness", stiffness, lower=0.0, strict=True, allow_inf=True)
    c, s2 = real_array("damping", damping, lower=0.0)
    k2, s3 = real_array("other_stiffness", other_stiffness, lower=0.0, strict=True, allow_inf=True)
    c2, s4 = real_array("other_damping", other_damping, lower=0.0)
    scalar = s1 and s2 and s3 and s4
    return finish(1.0 / (1.0 / k + 1.0 / k2), scalar), finish(c + c2, scalar)


def split_pair(
    *, stiffness: Any, damping: Any, other_stiffness: Any = np.inf, other_damping: Any = 0.1
) -> tuple[float | np.ndarray, float | np.ndarray]:
    """What to set on one body so that the pair has ``(stiffness, damping)``.

    Inverse of :func:`combine_pair` given the other body's values: ``k_A = 1 / (1/k -
    1/k_B)``, ``c_A = c - c_B``; ``ValueError`` where no non-negative value exists (the
    other body is already softer, or damps more). To give two equal bodies the pair
    ``(k, c)`` set each to ``(2 k, c / 2)`` (``split_pair(..., other_stiffness=2 k,
    other_damping=c / 2)``).

    >>> split_pair(stiffness=1e4, damping=40.1)
    (10000.0, 40.0)
    >>> split_pair(stiffness=5e3, damping=40.0, other_stiffness=1e4, other_damping=20.0)
    (10000.0, 20.0)
    """
    k, s1 = real_array("stiffness", stiffness, lower=0.0, strict=True)
    c, s2 = real_array("damping", damping, lower=0.0)
    k2, s3 = real_array("other_stiffness", other_stiffness, lower=0.0, strict=True, allow_inf=True)
    c2, s4 = real_array("other_damping", other_damping, lower=0.0)
    scalar = s1 and s2 and s3 and s4
    if np.any(k >= k2):
        raise ValueError(
            f"stiffness = {stiffness!r} cannot be reached: the other body's stiffness "
            f"{other_stiffness!r} is not larger (springs in series are softer than each)"
        )
    if np.any(c < c2):
        raise ValueError(
            f"damping = {damping!r} cannot be reached: the other body already brings "
            f"{other_damping!r} N s/m (PyBullet's default 0.1 unless changeDynamics sets it)"
        )
    with np.errstate(divide="ignore"):
        own = 1.0 / (1.0 / k - 1.0 / k2)
    return finish(own, scalar), finish(c - c2, scalar)
