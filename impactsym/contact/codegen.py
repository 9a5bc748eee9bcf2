"""The NumPy-only source of the section-2 contact functions that ``impactsym export`` writes.

The public functions of :mod:`impactsym.contact.api` are cut from the package's own
source (:mod:`impactsym.numeric.pysource`), with everything they use: the kernel of
:mod:`impactsym.contact.kernel` (ridge-bracketed Newton iteration, the limits), the
input checks and the root finder; the closed forms the kernel evaluates are the code
SymPy generated for the package (:func:`impactsym.numeric.codegen.lambdified_source`).
Only where the kernel builds its forms with SymPy (``PiecewiseInD.__init__``) does the
exported module take them from a table instead, so the exported functions compute the
package's numbers.
"""

from __future__ import annotations

import dataclasses

from impactsym.contact import api, kernel
from impactsym.numeric import codegen
from impactsym.numeric.codegen import lambdified_source
from impactsym.numeric.pysource import Cut, Text

#: ``PiecewiseInD.__init__`` of the exported module: the forms from :data:`FORMS`.
_INIT = """def __init__(
    self, name: str, with_tau: bool, critical_separate: bool, restart: bool = False
) -> None:
    # exported: the forms impactsym lambdified for this name, one per damping regime
    # (FORMS), evaluated as the package evaluates them (broadcast_evaluate)
    if restart:
        raise ValueError("contacts restarted from a state (z0, v0) are not exported")
    self.name = name
    self.critical_separate = critical_separate
    self.d_index = 1 if with_tau else 0
    self.functions = {r: partial(broadcast_evaluate, form) for r, form in FORMS[name].items()}"""

#: Per-condition functions of the closed forms (the names of the earlier exported module).
_CLOSED_FORMS = '''
def contact_function_{c}(tau: ArrayLike, D: ArrayLike, f: ArrayLike) -> ArrayLike:
    """Contact function g_{c}(tau; D, f) of the spring-damper contact (paper section 2).

    {what}.

    Arguments: tau (normalized time omega0 t >= 0), D (Lehr's damping, 0 to 1e8),
    f (pressing force F / (d v0) >= 0); NumPy arrays broadcast.
    """
    (t, damping, force), shape, scalar = _closed_form_inputs("{c}", tau=tau, D=D, f=f)
    return finish(kernels(condition="{c}").g(t, damping, force).reshape(shape), scalar)


def ridge_time_{c}(D: ArrayLike, f: ArrayLike) -> ArrayLike:
    """Ridge time tau_r(D, f) of the {c} condition: the first local minimum of g after
    impact, from dg/dtau = 0 (paper section 2, the fold of Fig. 1a); NaN where g has no
    minimum. ``ridge_time(D, f, condition="{c}")``.
    """
    return ridge_time(D, f, condition="{c}")


def boundary_{c}(D: ArrayLike, f: ArrayLike) -> ArrayLike:
    """Boundary function G(D, f) = g_{c}(tau_r(D, f), D, f) of the {c} condition
    (paper section 2, Fig. 1b): the body releases where G < 0 and sticks where G >= 0;
    where g has no minimum G is its infimum 2 D f. Arguments: D, f as above.
    """
    (damping, force), shape, scalar = _closed_form_inputs("{c}", D=D, f=f)
    return finish(boundary_value(damping, force, condition="{c}").reshape(shape), scalar)
'''

_WHAT = {
    "position": "The penetration z; contact lasts while g > 0",
    "force": "The normalized contact force 2 D z' + z; contact lasts while g > 0",
}

_RIDGE_TIME = '''
def _closed_form_inputs(condition, **arrays):
    """:func:`flat_inputs`, and ``D`` within the range of the closed forms."""
    flat, shape, scalar = flat_inputs(condition=condition, **arrays)
    damping = flat[list(arrays).index("D")]
    if np.any(damping > D_FAR):
        raise ValueError(
            f"D must be <= {D_FAR:g} (the range of these closed forms), "
            f"got {float(damping[damping > D_FAR][0])!r}"
        )
    return flat, shape, scalar


def ridge_time(D: ArrayLike, f: ArrayLike, *, condition: str) -> ArrayLike:
    r"""Ridge time :math:`\\tau_r(D, f)`: the first local minimum of ``g`` after impact.

    The fold :math:`\\partial g/\\partial\\tau = 0` of the surface :math:`g(\\tau, D, f)
    = 0` (paper section 2, Fig. 1a), in closed form per damping regime; it brackets the
    contact time (the body sticks where :math:`g(\\tau_r) \\ge 0`). The third result of
    ``impactsym.contact.contact_surface`` where that is defined.

    Parameters
    ----------
    D : float or array_like
        Lehr's damping ratio, ``0 <= D <= 1e8`` (beyond, the closed forms lose accuracy).
    f : float or array_like
        Pressing force over damper force at impact, ``>= 0``.
    condition : {"force", "position"}
        The contact function ``g``: the contact force or the penetration.

    Returns
    -------
    float or ndarray
        :math:`\\tau_r`, broadcast over ``D`` and ``f``; ``nan`` where ``g`` has no minimum.

    Examples
    --------
    >>> round(ridge_time(0.0, 1.0, condition="force") / np.pi, 12)
    1.5
    """
    (damping, force), shape, scalar = _closed_form_inputs(condition, D=D, f=f)
    return finish(ridge(damping, force, condition=condition).reshape(shape), scalar)
'''

#: Public names of the section-2 part of the exported module.
CONTACT_EXPORTS = (
    "contact_time",
    "restitution",
    "stick_boundary",
    "ridge_time",
    "contact_surface",
    "physical_contact",
    "PhysicalContact",
    *(f"{kind}_{c}" for c in ("position", "force") for kind in ("contact_function", "ridge_time")),
    "boundary_position",
    "boundary_force",
)


def form_pieces() -> list[str]:
    """The lambdified forms of the kernel (first impact) and the table ``FORMS`` of them.

    The forms are taken from the package's own kernel objects, so the exported module
    has the regimes and the code the package evaluates.
    """
    pieces, table = [], []
    objects = [
        getattr(kernel.kernels(condition=c), field.name)
        for c in ("position", "force")
        for field in dataclasses.fields(kernel.Kernels)
    ]
    for piecewise in [*objects, kernel.z_dot()]:
        entries = []
        for regime, function in piecewise.functions.items():
            name = f"_{piecewise.name}_{regime}"
            doc = f"Numeric form {piecewise.name} of the contact, {regime} regime."
            pieces.append(lambdified_source(function, name, doc))
            entries.append(f'"{regime}": {name}')
        table.append(f'    "{piecewise.name}": {{{", ".join(entries)}}},')
    doc = "#: The lambdified forms by name and damping regime (impactsym.contact.derivation)."
    pieces.append("\n".join([doc, "FORMS = {", *table, "}"]))
    return pieces


def contact_items() -> list[Cut | Text | str]:
    """What the exported section-2 functions (:data:`CONTACT_EXPORTS`) are made of, for
    :func:`impactsym.numeric.pysource.collect` (which adds what they use)."""
    required = ("condition",)
    public = ("contact_time", "restitution", "stick_boundary", "contact_surface")
    closed = [_CLOSED_FORMS.format(c=c, what=_WHAT[c]) for c in ("position", "force")]
    return [
        "# -- spring-damper contact (paper section 2): impactsym.contact.api",
        *(Cut(api, name, required=required) for name in public),
        Cut(api, "PhysicalContact"),
        Cut(api, "physical_contact", required=required),
        "# -- ridge times and the closed forms per condition (this module's own)",
        Text(_RIDGE_TIME, api),
        *(Text(text, api) for text in closed),
        "# -- the closed forms of impactsym.contact.derivation, as SymPy generated them",
        Cut(kernel, "PiecewiseInD", replace=(("__init__", _INIT),)),
        Cut(codegen, "broadcast_evaluate"),
        *(Text(piece) for piece in form_pieces()),
    ]
