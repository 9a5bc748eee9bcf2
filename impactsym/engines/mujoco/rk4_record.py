"""MuJoCo's RK4 contact record: the engine's result plus which stages were in contact.

RK4's restitution and contact time jump not only where the end step changes but also
where a stage of some step (the entering step, the steps that end the contact) reaches
or leaves the contact (``x > 0``, `docs/physics.md`, *MuJoCo's RK4 step*) while its
force term ``g + b v + d k x`` is positive: the force at ``x = 0+`` is ``d' (g + b v)``,
not 0. A stage's bit is set where it is in contact (``x > 0``): it flips at every such
jump (and, needlessly but harmlessly, where a stage without force crosses ``x = 0``).
A jump moves the later states at once, so other stages may flip at the same phase (one
of the next step leaving as one of this step enters: a count would stay the same).
Where the force term of a stage in contact crosses zero the force is clipped: a kink,
not a jump, which the bits do not show (marking kinks too took 3.7 times the CPU).
:attr:`RK4Contact.stage_pattern` therefore keeps the stages' place, and
:func:`~impactsym.engines.mujoco.discrete.phase_summary` sees every such jump as a change
of its piece key.

SI: seconds, metres, m/s, m/s^2.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from impactsym.engines.mujoco.stepping import StepContact

__all__ = ["PATTERN_BITS", "RK4Contact", "pattern_bits", "stage_bits"]

#: bits of :attr:`RK4Contact.stage_pattern`: the stage bits of 7 consecutive steps
PATTERN_BITS = 28


@dataclass(frozen=True, eq=False)
class RK4Contact(StepContact):
    """:class:`~impactsym.engines.mujoco.stepping.StepContact` of an RK4 contact (arrays).

    Attributes
    ----------
    stage_pattern
        The :func:`stage_bits` of the steps from the entering step (step 0) to the end
        state, XOR-folded by :func:`pattern_bits` (integers below ``2^28``). Two phases
        with the same end step and a different pattern differ in some stage's contact.
    """

    stage_pattern: np.ndarray


def stage_bits(*penetrations: np.ndarray) -> np.ndarray:
    """Bit ``i`` for stage ``i + 1`` of a step, given its four stage penetrations: set
    where the stage is in contact (``x > 0``)."""
    out = np.zeros(np.shape(penetrations[0]), np.int64)
    for i, x in enumerate(penetrations):
        out |= (np.asarray(x) > 0).astype(np.int64) << i
    return out


def pattern_bits(bits: np.ndarray, step: np.ndarray, skip: np.ndarray) -> np.ndarray:
    """Step ``step``'s share of :attr:`RK4Contact.stage_pattern` (0 where ``skip``).

    Its :func:`stage_bits` at bit ``4 step mod 28``: a stage that flips flips one bit,
    and only flips in steps 7 apart can cancel. A step with all four stages in contact
    adds nothing, so the closed-form jumps through the interior need no bookkeeping.
    """
    shift = (4 * np.asarray(step, np.int64)) % PATTERN_BITS
    return np.where(skip | (bits == 15), 0, np.left_shift(bits, shift))
