"""The unilateral spring-damper contact (paper section 2).

* :mod:`~impactsym.contact.derivation` -- SymPy: the normalized solution in every damping
  regime, the contact functions of both conditions, the ridge and the stick/release
  boundary (:class:`SpringDamperContact`);
* :mod:`~impactsym.contact.kernel` -- internal: those closed forms lambdified and evaluated
  piecewise in ``D``, the ridge-bracketed contact-time root, the limits;
* :mod:`~impactsym.contact.unpressed` -- the contact time and restitution without
  pressing force in closed form, for both conditions;
* :mod:`~impactsym.contact.extrema` -- the maximum penetration and peak force of the
  linear contact in closed form, with or without pressing force;
* :mod:`~impactsym.contact.api` -- the public functions on that kernel:
  :func:`contact_time`, :func:`restitution`, :func:`stick_boundary`,
  :func:`contact_surface`, and :func:`physical_contact` in physical units;
* :mod:`~impactsym.contact.release` -- the loaded oscillator with an offset force threshold
  and two thresholds, solved once for the engine models (:func:`linear_release`);
* :mod:`~impactsym.contact.flight` -- SymPy: the free flight after a release and the
  relaxing element (the re-contact equation);
* :mod:`~impactsym.contact.bounce` -- the bounce sequence until rest
  (:func:`bounce_sequence`, :func:`bounce_map`, :func:`physical_bounce`), on the one
  event loop of :mod:`~impactsym.contact.loop`;
* :mod:`~impactsym.contact.laws` -- SymPy: the nonlinear contact laws (linear,
  hertz-linear, Hunt–Crossley, Tsuji, viscoelastic) and their normalization
  (:class:`ContactLaw`); :mod:`~impactsym.contact.lawmaps` their closed forms
  (:class:`HuntCrossleyClosedForm`, :class:`TsujiMap`);
* :mod:`~impactsym.contact.nonlinear` -- one impact on any law in physical units
  (:func:`impact`); :mod:`~impactsym.contact.lawdesign` the damping that delivers a
  restitution (:func:`damping_for`), on the array integrator of
  :mod:`~impactsym.contact.lawkernel`;
* :mod:`~impactsym.contact.lawstick`, :mod:`~impactsym.contact.lawgrid`,
  :mod:`~impactsym.contact.lawbounce` -- the paper's questions for every law: the stick
  boundary f*(damping number) (:func:`law_stick_boundary`), contact-time and restitution
  maps (:func:`law_contact_map`) and the bounce sequence (``bounce_sequence(..., law=)``),
  on one impact in the law's numbers (:mod:`~impactsym.contact.lawnumbers`);
* :mod:`~impactsym.contact.viscoseries` -- the viscoelastic restitution as a series in
  its damping number, derived to any order (:func:`viscoelastic_restitution_series`).
"""

from __future__ import annotations

from impactsym._lazy import lazy_names

_NAMES = {
    "contact_time": "impactsym.contact.api",
    "restitution": "impactsym.contact.api",
    "stick_boundary": "impactsym.contact.api",
    "contact_surface": "impactsym.contact.api",
    "physical_contact": "impactsym.contact.api",
    "PhysicalContact": "impactsym.contact.api",
    "bounce_sequence": "impactsym.contact.bounce",
    "bounce_map": "impactsym.contact.bounce",
    "physical_bounce": "impactsym.contact.bounce",
    "BounceSequence": "impactsym.contact.bounce",
    "SpringDamperContact": "impactsym.contact.derivation",
    "SpringDamperRestart": "impactsym.contact.derivation",
    "regime_of": "impactsym.contact.derivation",
    "impact": "impactsym.contact.nonlinear",
    "NonlinearImpact": "impactsym.contact.nonlinear",
    "damping_for": "impactsym.contact.lawdesign",
    "ContactLaw": "impactsym.contact.laws",
    "contact_law": "impactsym.contact.laws",
    "LAWS": "impactsym.contact.laws",
    "HuntCrossleyClosedForm": "impactsym.contact.lawmaps",
    "TsujiMap": "impactsym.contact.lawmaps",
    "law_stick_boundary": "impactsym.contact.lawstick",
    "law_contact_map": "impactsym.contact.lawgrid",
    "LawContactMap": "impactsym.contact.lawgrid",
    "viscoelastic_restitution_series": "impactsym.contact.viscoseries",
}
__all__ = sorted(_NAMES)
__getattr__, __dir__ = lazy_names(__name__, _NAMES)
