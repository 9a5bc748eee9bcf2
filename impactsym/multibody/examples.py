r"""The two planar example systems of the multibody analysis (paper section 3).

A falling bar and a double pendulum striking a wall, written as hand-built SymPy
matrices ``M(q) q'' = F(q, q') + n(q) lambda`` with a penetration ``g(q)`` and an impact
state; their effective contact masses differ clearly from every body mass, which makes
them a test of the reduction (``docs/physics.md``, section 3). Also importable from
:mod:`impactsym.multibody.simulation`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import sympy as sp

from impactsym.multibody.oscillator import ReducedContact
from impactsym.multibody.reduction import reduce_contact
from impactsym.validation import reject_strings


@dataclass(frozen=True)
class MultibodyExample:
    """A planar multibody system at the instant of impact, with numeric parameters.

    ``M(q) q'' = F(q, q') + n(q) lambda`` with penetration ``g(q)``; the impact state is
    ``q0`` and the velocity ``speed * direction``.
    """

    name: str
    title: str
    M: sp.Matrix
    F: sp.Matrix
    g: sp.Expr
    q: tuple[sp.Symbol, ...]
    qd: tuple[sp.Symbol, ...]
    q0: tuple[float, ...]
    direction: tuple[float, ...]

    def at(self, speed: float) -> dict[sp.Symbol, float]:
        """The impact state for the velocity ``speed * direction``.

        >>> falling_bar().at(2.0)[sp.Symbol("v_y")]
        -2.0
        """
        reject_strings("speed", speed)
        state = dict(zip(self.q, self.q0, strict=True))
        state.update({u: speed * c for u, c in zip(self.qd, self.direction, strict=True)})
        return state

    def reduce(
        self,
        k: Any = 1.0,
        d: Any = 0.0,
        speed: Any = 1.0,
        *,
        projection: str = "impulse",
        simplify: bool = True,
    ) -> ReducedContact:
        """The reduced contact oscillator at impact speed ``speed`` (see
        :func:`impactsym.multibody.reduce_contact`).

        >>> r = falling_bar().reduce(1e4, 10.0, 0.5)
        >>> round(r.m_eff, 6), round(r.load, 4)  # 4/13 kg; load: weight and drag, reduced
        (0.307692, 5.5214)
        """
        return reduce_contact(
            self.M,
            self.F,
            self.g,
            self.q,
            self.qd,
            self.at(speed),
            k,
            d,
            projection=projection,
            simplify=simplify,
        )


def falling_bar(
    *,
    mass: float = 1.0,
    length: float = 1.0,
    angle: float = np.pi / 6,
    gravity: float = 9.81,
    drag: float = 0.5,
    rotational_drag: float = 2.0,
) -> MultibodyExample:
    r"""A rigid bar (centre ``x, y``, angle ``theta``) falling onto its lower end.

    The end at ``(x, y) - L/2 (cos theta, sin theta)`` hits the ground ``y = 0``; viscous
    drag ``drag * v`` on the centre and ``rotational_drag * theta'`` on the rotation. The
    bar falls straight down at the impact angle.

    .. math:: \tilde m = \frac{m}{1 + 3\cos^2\vartheta}

    >>> bar = falling_bar()
    >>> round(bar.reduce().m_eff * 13 / 4, 12)  # theta = 30 degrees: m~ = 4 m / 13
    1.0
    """
    x, y, th = sp.symbols("x y theta")
    vx, vy, om = sp.symbols("v_x v_y omega")
    inertia = mass * length**2 / 12
    M = sp.diag(mass, mass, inertia)
    F = sp.Matrix([-drag * vx, -mass * gravity - drag * vy, -rotational_drag * om])
    g = length / 2 * sp.sin(th) - y
    q0 = (0.0, length / 2 * float(np.sin(angle)), float(angle))
    return MultibodyExample(
        "bar", "falling bar", M, F, g, (x, y, th), (vx, vy, om), q0, (0.0, -1.0, 0.0)
    )


def double_pendulum(
    *,
    masses: tuple[float, float] = (1.0, 0.5),
    lengths: tuple[float, float] = (1.0, 0.7),
    angles: tuple[float, float] = (np.pi / 9, np.pi / 4),
    gravity: float = 9.81,
    joint_stiffness: tuple[float, float] = (50.0, 20.0),
    joint_rest: tuple[float, float] = (1.5, 1.382),
    joint_damping: tuple[float, float] = (1.0, 0.5),
) -> MultibodyExample:
    r"""A double pendulum with elastic, damped joints whose tip strikes a vertical wall.

    Absolute link angles ``q1, q2`` from the downward vertical, point masses at the
    link ends, torsional springs and dampers at the shoulder (``q1``) and the elbow
    (``q2 - q1``); the wall ``x = l1 sin a1 + l2 sin a2`` is placed where the tip is at
    the impact angles ``a1, a2``. The links swing together (``q1' = q2'``).

    .. math:: g(q) = l_1 \sin q_1 + l_2 \sin q_2 - x_{\mathrm{wall}}

    >>> pendulum = double_pendulum()
    >>> round(pendulum.reduce().m_eff, 6)  # between the tip mass 0.5 and the total 1.5
    0.92423
    """
    q1, q2 = sp.symbols("q1 q2")
    u1, u2 = sp.symbols("u1 u2")
    (m1, m2), (l1, l2) = masses, lengths
    (k1, k2), (r1, r2), (c1, c2) = joint_stiffness, joint_rest, joint_damping
    c12 = sp.cos(q1 - q2)
    M = sp.Matrix([[(m1 + m2) * l1**2, m2 * l1 * l2 * c12], [m2 * l1 * l2 * c12, m2 * l2**2]])
    s12 = sp.sin(q1 - q2)
    F = sp.Matrix(
        [
            -m2 * l1 * l2 * s12 * u2**2
            - (m1 + m2) * gravity * l1 * sp.sin(q1)
            - k1 * (q1 - r1)
            + k2 * (q2 - q1 - r2)
            - c1 * u1
            + c2 * (u2 - u1),
            m2 * l1 * l2 * s12 * u1**2
            - m2 * gravity * l2 * sp.sin(q2)
            - k2 * (q2 - q1 - r2)
            - c2 * (u2 - u1),
        ]
    )
    a1, a2 = (float(a) for a in angles)
    wall = l1 * np.sin(a1) + l2 * np.sin(a2)
    g = l1 * sp.sin(q1) + l2 * sp.sin(q2) - wall
    return MultibodyExample(
        "pendulum", "double pendulum", M, F, g, (q1, q2), (u1, u2), (a1, a2), (1.0, 1.0)
    )


def examples() -> tuple[MultibodyExample, MultibodyExample]:
    """The two systems of the agreement study: :func:`falling_bar`, :func:`double_pendulum`.

    >>> [example.name for example in examples()]
    ['bar', 'pendulum']
    """
    return falling_bar(), double_pendulum()
