"""Hostile input for the engines wing (impactsym.engines): extremes of scale, wrong types,
NaN, inf, negative and empty input, result objects under == and hash.

Every refusal is a ValueError or TypeError raised early that names the offending
argument; every answer at the extremes is checked against SciPy's event integration of
the engine's own continuous law (in its natural units, where the SI numbers overflow).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from references.mujoco_law import mujoco_contact
from scipy.integrate import solve_ivp

from impactsym.cli import main
from impactsym.engines import lammps, mujoco

FLAT = (0.9, 0.9, 0.001, 0.5, 2.0)


def _dashpot(stiffness, damping, *, force=True):
    """``x'' = -(stiffness x + damping x')``, ``x(0) = 0``, ``x'(0) = 1``, to its release.

    Returns ``(restitution, contact_time, max_penetration)`` from SciPy's events: the
    force ``stiffness x + damping x'`` (if ``force``) or the overlap reaching zero.
    """

    def rhs(t, y):
        return [y[1], -(stiffness * y[0] + damping * y[1])]

    def overlap(t, y):
        return y[0] if t > 1e-12 else 1.0

    def dashpot_force(t, y):
        return stiffness * y[0] + damping * y[1]

    overlap.terminal = dashpot_force.terminal = True
    overlap.direction = dashpot_force.direction = -1
    events = [dashpot_force, overlap] if force else [overlap]
    sol = solve_ivp(
        rhs, (0, 100.0), [0.0, 1.0], events=events, rtol=1e-12, atol=1e-15, dense_output=True
    )
    assert sol.status == 1
    t_end = sol.t[-1]
    x = sol.sol(np.linspace(0.0, t_end, 20001))[0]
    return -sol.y[1, -1], t_end, x.max()


# -- LAMMPS: scale ----------------------------------------------------------------------------


@pytest.mark.parametrize("scale", [1e160, 1e-200, 1e300])
def test_lammps_prediction_is_scale_free(scale):
    # kn = eta = m = scale is x'' = -(x + x') in SI (kn/m = eta/m = 1 exactly): e = 0.298
    e, t_c, x_max = _dashpot(1.0, 1.0)
    c = lammps.predict(kn=scale, damping=scale, mass=scale, speed=1.0)
    assert c.restitution == pytest.approx(e, rel=1e-8)
    assert c.contact_time == pytest.approx(t_c, rel=1e-8)
    assert c.max_penetration == pytest.approx(x_max, rel=1e-7)
    assert c.damping_ratio == pytest.approx(0.5, rel=1e-15)
    assert not c.sticks


def test_lammps_stiff_light_contact_where_kn_over_m_overflows():
    # kn / m = 1e310 overflows, sqrt(kn m) = 1e145; in time units 1/omega0 = 1e-155 s the
    # law is z'' = -(z + z') again
    e, t_c, x_max = _dashpot(1.0, 1.0, force=False)
    c = lammps.predict(kn=1e300, damping=1e145, mass=1e-10, speed=2.0, limit_damping=False)
    assert c.restitution == pytest.approx(e, rel=1e-8)
    assert c.contact_time == pytest.approx(t_c * 1e-155, rel=1e-8)
    assert c.max_penetration == pytest.approx(2.0 * x_max * 1e-155, rel=1e-7)


def test_lammps_quantities_beyond_the_float_range_are_refused_by_name():
    with pytest.raises(ValueError, match="damping ratio.*damping = 1e"):
        lammps.predict(kn=1e-300, damping=1e300, mass=1e-300, speed=1.0)
    with pytest.raises(ValueError, match="gravity"):
        lammps.predict(kn=1e-300, damping=0.0, mass=1e300, speed=1e-300, gravity=1e300)


def test_hooke_for_huge_mass_meets_its_targets_or_refuses_by_name():
    c = lammps.hooke_for(restitution=0.5, contact_time=1e-3, mass=1e300)
    # the design's own law, in units of the contact time: x'' = -(kn/m) x - (eta/m) x'
    e, t_c, _ = _dashpot(c.kn / 1e300 * 1e-6, c.damping / 1e300 * 1e-3)
    assert e == pytest.approx(0.5, rel=1e-8)
    assert t_c * 1e-3 == pytest.approx(1e-3, rel=1e-8)
    assert c.restitution == pytest.approx(0.5, rel=1e-10)
    assert c.contact_time == pytest.approx(1e-3, rel=1e-10)
    with pytest.raises(ValueError, match=r"kn = m omega0\^2 is beyond the float range.*mass"):
        lammps.hooke_for(restitution=0.5, contact_time=1e-3, mass=1e305)
    with pytest.raises(ValueError, match="beyond the float range.*contact_time = 1e-300"):
        lammps.hooke_for(restitution=0.5, contact_time=1e-300, mass=1e10)


def test_hooke_for_refuses_a_design_that_misses_its_target(monkeypatch):
    # the check itself: a prediction that disagrees with the design is refused, naming it
    real = lammps.predict

    def off(**kwargs):
        return real(**{**kwargs, "kn": kwargs["kn"] * 1.01})

    monkeypatch.setattr(lammps.design, "predict", off)
    with pytest.raises(ValueError, match=r"restitution = 0.5 with contact_time = 0.001 .*not"):
        lammps.hooke_for(restitution=0.5, contact_time=1e-3, mass=1.0)


# -- LAMMPS: coeff_restitution's floor --------------------------------------------------------


def test_coeff_restitution_floor_is_exp_minus_2():
    # the critically damped force condition (reference: SciPy's events) is the floor
    e_floor, t_c, _ = _dashpot(1.0, 2.0)
    assert e_floor == pytest.approx(math.exp(-2), rel=1e-9)
    assert t_c == pytest.approx(2.0, rel=1e-9)
    above = math.exp(-2) * (1 + 1e-3)
    e_in = lammps.coeff_restitution_for(above)
    assert 0 < e_in < 1e-30  # tiny, but a float LAMMPS takes
    assert lammps.coeff_restitution_achieved(e_in) == pytest.approx(above, rel=1e-9)
    for e in (math.exp(-2), math.exp(-2) * (1 - 1e-12), 0.1, math.exp(-2) * (1 + 1e-6)):
        with pytest.raises(ValueError, match=r"restitution = .*e <= exp\(-2\) = 0.135335"):
            lammps.coeff_restitution_for(e)
    doc = lammps.coeff_restitution_for.__doc__
    assert "exp(-2)" in doc
    assert "0.0016" not in doc


# -- LAMMPS: types and values -----------------------------------------------------------------

LAMMPS_OK = {"kn": 1e5, "damping": 50.0, "mass": 1.0, "speed": 1.0, "gravity": 0.0}


@pytest.mark.parametrize("value", ["no", "", None, 1, 0, "False", np.array([True])])
def test_limit_damping_must_be_a_bool(value):
    with pytest.raises(TypeError, match="limit_damping must be True or False"):
        lammps.predict(**LAMMPS_OK, limit_damping=value)
    with pytest.raises(TypeError, match="limit_damping must be True or False"):
        lammps.hooke_for(restitution=0.5, contact_time=1e-3, mass=1.0, limit_damping=value)
    assert lammps.predict(**LAMMPS_OK, limit_damping=np.False_).limit_damping is False


@pytest.mark.parametrize("name", ["kn", "damping", "mass", "speed", "gravity"])
@pytest.mark.parametrize(
    ("bad", "error"),
    [
        ("1", TypeError),
        (math.nan, ValueError),
        (math.inf, ValueError),
        (-1.0, ValueError),
        (True, TypeError),
        ([1.0, True], TypeError),
    ],
)
def test_lammps_predict_names_every_bad_input(name, bad, error):
    with pytest.raises(error, match=name):
        lammps.predict(**{**LAMMPS_OK, name: bad})


@pytest.mark.parametrize("name", ["restitution", "contact_time", "mass"])
@pytest.mark.parametrize(
    ("bad", "error"),
    [
        ("0.5", TypeError),
        (math.nan, ValueError),
        (math.inf, ValueError),
        (-0.5, ValueError),
        (False, TypeError),
    ],
)
def test_hooke_for_names_every_bad_input(name, bad, error):
    ok = {"restitution": 0.5, "contact_time": 1e-3, "mass": 1.0}
    with pytest.raises(error, match=name):
        lammps.hooke_for(**{**ok, name: bad})


def test_lammps_shapes_empty_and_results_under_eq_and_hash():
    with pytest.raises(ValueError, match=r"kn \(shape \(2,\)\) and damping \(shape \(3,\)\)"):
        lammps.predict(kn=np.ones(2), damping=np.ones(3), mass=1.0, speed=1.0)
    with pytest.raises(ValueError, match=r"restitution \(shape \(2,\)\) and contact_time"):
        lammps.hooke_for(restitution=[0.3, 0.5], contact_time=[1e-3] * 3, mass=1.0)
    with pytest.raises(ValueError, match="mass must be one number"):
        lammps.predict(kn=1.0, damping=1.0, mass=[1.0, 2.0], speed=1.0)
    empty = lammps.predict(kn=np.array([]), damping=1.0, mass=1.0, speed=1.0)
    assert empty.restitution.shape == empty.contact_time.shape == (0,)
    assert lammps.hooke_for(restitution=np.array([]), contact_time=1e-3, mass=1.0).kn.shape == (0,)
    a = lammps.predict(kn=np.array([1.0, 2.0]), damping=0.5, mass=1.0, speed=1.0)
    b = lammps.predict(kn=np.array([1.0, 2.0]), damping=0.5, mass=1.0, speed=1.0)
    c = lammps.predict(kn=np.array([1.0, 3.0]), damping=0.5, mass=1.0, speed=1.0)
    assert a == b
    assert a != c
    assert a != "a"
    assert hash(a) == hash(b)  # arrays stay out of the hash; equal records hash alike
    assert len({a, b, c}) == 2
    one = lammps.predict(kn=1.0, damping=0.5, mass=1.0, speed=1.0)
    assert one == lammps.predict(kn=1.0, damping=0.5, mass=1.0, speed=1.0)
    assert hash(one) == hash(lammps.predict(kn=1.0, damping=0.5, mass=1.0, speed=1.0))


# -- MuJoCo: scale ----------------------------------------------------------------------------


def _mujoco_reference(d, dampratio, dmax=None):
    """MuJoCo's law at constant impedance ``d`` in units of the timeconst.

    ``b = 2 / (d_max tc)``, ``kbar = 1 / (d_max tc dampratio)^2`` (``d_max = solimp[1]``)
    and ``x'' = -d (b x' + d kbar x)``.
    """
    dmax = d if dmax is None else dmax
    b, kbar = 2 / dmax, 1 / (dmax**2 * dampratio**2)
    return _dashpot(d * d * kbar, d * b)


@pytest.mark.parametrize("timeconst", [1e-160, 1e160, 1e-300])
def test_mujoco_flat_prediction_is_scale_free(timeconst):
    e, t_c, x_max = _mujoco_reference(0.9, 1.0)
    assert e == pytest.approx(math.exp(-2), rel=1e-9)  # D = dampratio = 1: force condition
    p = mujoco.predict(solref=(timeconst, 1.0), solimp=FLAT, speed=1.0)
    assert p.restitution == pytest.approx(e, rel=1e-9)
    assert p.contact_time / timeconst == pytest.approx(t_c, rel=1e-9)
    assert p.max_penetration / timeconst == pytest.approx(x_max, rel=1e-7)
    assert not p.sticks


@pytest.mark.parametrize(("timeconst", "d"), [(1e-160, 0.9), (1e160, 0.95)])
def test_mujoco_varying_prediction_is_scale_free(timeconst, d):
    # far below the impedance width (1e-160 m) the impedance is d_min, far beyond it d_max
    e, t_c, _ = _mujoco_reference(d, 1.0, dmax=0.95)
    p = mujoco.predict(solref=(timeconst, 1.0), solimp=mujoco.DEFAULT_SOLIMP, speed=1.0)
    # the Runge-Kutta step's accuracy, as at ordinary scales (tc = 1e3 s: same regime)
    assert p.restitution == pytest.approx(e, rel=3e-4)
    assert p.contact_time / timeconst == pytest.approx(t_c, rel=3e-4)
    ordinary = mujoco.predict(
        solref=(1e6 if timeconst > 1 else 1e-9, 1.0), solimp=mujoco.DEFAULT_SOLIMP, speed=1.0
    )
    assert p.restitution == pytest.approx(ordinary.restitution, rel=1e-8)


def test_mujoco_stiffness_form_beyond_kbar_range():
    # (-K, -B) at d = d_max = 0.9: kbar = K / 0.81 = 1.2e300 (kbar tc^2 of the positive form
    # would overflow for tc ~ 1e-155); omega0 = sqrt(K) = 1e150, D = B / (2 sqrt(K)) = 0.5
    e, t_c, _ = _dashpot(1.0, 1.0)
    p = mujoco.predict(solref=(-1e300, -1e150), solimp=FLAT, speed=1.0)
    assert p.restitution == pytest.approx(e, rel=1e-9)
    assert p.contact_time * math.sqrt(1e300) == pytest.approx(t_c, rel=1e-9)


def test_mujoco_quantities_beyond_the_float_range_are_refused_by_name():
    # static penetration g / omega0^2 ~ 1e320 m
    with pytest.raises(ValueError, match=r"solref = \(1e\+160, 1.0\).*beyond the float range"):
        mujoco.predict(solref=(1e160, 1.0), solimp=FLAT, speed=1.0, gravity=9.81)
    with pytest.raises(ValueError, match="speed = 1.0 and gravity = 9.81"):
        mujoco.predict(solref=(1e160, 1.0), speed=1.0, gravity=9.81)
    with pytest.raises(ValueError, match=r"solref = \(5e-324, 1.0\).*beyond the float range"):
        mujoco.predict(solref=(5e-324, 1.0), solimp=FLAT, speed=1.0)


# -- MuJoCo: obscure errors -------------------------------------------------------------------


def test_solref_for_says_the_body_starts_to_stick():
    kw = {"speed": 1.0, "gravity": 9.81, "contact_time": 0.01, "solimp": FLAT}
    with pytest.raises(ValueError, match=r"restitution = 0.05 .*starts to stick at dampratio"):
        mujoco.solref_for(restitution=0.05, **kw)
    # the cause, in the model: with a little more damping every timeconst that gives a
    # contact time as long as 0.01 s makes the body stick
    tcs = np.geomspace(1e-4, 1.0, 2001)
    p = mujoco.predict(solref=(tcs, np.full(tcs.size, 1.2)), solimp=FLAT, speed=1.0, gravity=9.81)
    assert p.sticks.any()
    assert np.max(p.contact_time[~p.sticks]) < 0.01


def test_tiny_solimp_d_min_is_integrated_not_an_overflow():
    # d_min = 1e-300 (MuJoCo clamps the impedance to >= 1e-4): the step-size estimate
    # used d_min unclamped and overflowed; against SciPy's events on the same law
    solimp = (1e-300, 0.95, 0.001, 0.5, 2.0)
    e, t_c, _ = mujoco_contact((0.02, 0.3), solimp, 1.0)  # max_step tc/200 = 1e-4
    p = mujoco.predict(solref=(0.02, 0.3), solimp=solimp, speed=1.0)
    # the fixed Runge-Kutta step resolves this steep impedance (1e-4 to 0.95 within 1 mm)
    # to 2e-6 (the reference is converged to 1e-12: max_step 1e-4 and 2e-6 agree)
    assert p.restitution == pytest.approx(e, rel=1e-5)
    assert p.contact_time == pytest.approx(t_c, rel=1e-6)
    argv = ["mujoco", "--restitution", ".5", "--speed", "1", "--solimp", "1e-300"]
    assert main([*argv, ".95", ".001", ".5", "2"]) == 0


def test_cli_mujoco_singular_design_is_a_named_refusal(capsys):
    argv = ["mujoco", "--restitution", "0.5", "--speed", "0.001", "--gravity", "9.81"]
    assert main([*argv, "--contact-time", "0.01"]) == 2
    err = capsys.readouterr().err
    assert "Singular matrix" not in err
    assert "restitution = 0.5 with contact_time = 0.01 s" in err
    assert "sticks" in err


@pytest.mark.parametrize(
    ("kwargs", "error", "name"),
    [
        ({"solref": 5}, TypeError, "solref must be a pair"),
        ({"solref": iter([0.02, 1.0])}, TypeError, "solref must be a pair"),
        ({"solref": "0.02 1"}, TypeError, "solref must be a pair"),
        ({"solref": (0.02, "1")}, TypeError, r"solref\[1\]"),
        ({"solref": (math.nan, 1.0)}, ValueError, r"solref\[0\]"),
        ({"solref": (0.02, math.inf)}, ValueError, r"solref\[1\]"),
        ({"solref": (True, 1.0)}, TypeError, r"solref\[0\]"),
        ({"solref": (np.ones(2), np.ones(3))}, ValueError, r"solref\[0\] \(shape \(2,\)\)"),
        ({"solref": (np.ones(2), np.ones(2)), "speed": np.ones(3)}, ValueError, "speed"),
        ({"solimp": 5}, TypeError, "solimp"),
        ({"solimp": (0.9, 0.95)}, TypeError, "solimp"),
        ({"solimp": (0.9, "0.95", 0.001)}, TypeError, r"solimp\[1\]"),
        ({"solimp": (0.9, math.nan, 0.001)}, ValueError, r"solimp\[1\]"),
        ({"solimp": (0.9, [0.9, 0.95], 0.001)}, TypeError, "solimp"),
        ({"speed": "1"}, TypeError, "speed"),
        ({"speed": -1.0}, ValueError, "speed"),
        ({"speed": math.nan}, ValueError, "speed"),
        ({"gravity": math.inf}, ValueError, "gravity"),
        ({"gravity": True}, TypeError, "gravity"),
        ({"mass": [1.0, 2.0]}, ValueError, "mass"),
        ({"timestep": -1e-3}, ValueError, "timestep"),
    ],
)
def test_mujoco_predict_names_every_bad_input(kwargs, error, name):
    ok = {"solref": (0.02, 1.0), "solimp": mujoco.DEFAULT_SOLIMP, "speed": 1.0}
    with pytest.raises(error, match=name):
        mujoco.predict(**{**ok, **kwargs})


def test_mujoco_empty_arrays_and_results_under_eq_and_hash():
    for solimp in (mujoco.DEFAULT_SOLIMP, FLAT):
        p = mujoco.predict(solref=(np.array([]), np.array([])), solimp=solimp, speed=1.0)
        assert p.restitution.shape == p.sticks.shape == (0,)
        d = mujoco.solref_for(restitution=np.array([]), speed=1.0, solimp=solimp)
        assert d.solref[0].shape == (0,)
    with pytest.warns(RuntimeWarning, match="unstable"):
        mujoco.predict(solref=(np.array([0.02]), 0.01), speed=1.0, timestep=0.002)
    mujoco.predict(solref=(np.array([]), np.array([])), speed=1.0, timestep=0.01)
    a = mujoco.predict(solref=(np.array([0.02, 0.03]), 1.0), solimp=FLAT, speed=1.0)
    b = mujoco.predict(solref=(np.array([0.02, 0.03]), 1.0), solimp=FLAT, speed=1.0)
    c = mujoco.predict(solref=(np.array([0.02, 0.04]), 1.0), solimp=FLAT, speed=1.0)
    assert a == b
    assert a != c
    assert hash(a) == hash(b)
    assert len({a, b, c}) == 2
    design = mujoco.solref_for(restitution=np.array([0.4, 0.6]), speed=1.0, solimp=FLAT)
    assert design == mujoco.solref_for(restitution=np.array([0.4, 0.6]), speed=1.0, solimp=FLAT)
    again = mujoco.solref_for(restitution=np.array([0.4, 0.6]), speed=1.0, solimp=FLAT)
    assert hash(design) == hash(again)
    one = mujoco.solref_for(restitution=0.5, speed=1.0, solimp=FLAT)
    assert hash(one) == hash(mujoco.solref_for(restitution=0.5, speed=1.0, solimp=FLAT))


# -- the lammps command -----------------------------------------------------------------------


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--restitution", "1.5", "--contact-time", "1e-3", "--mass", "1"], "restitution"),
        (["--restitution", "0.5", "--contact-time", "-1", "--mass", "1"], "contact_time"),
        (["--restitution", "0.5", "--contact-time", "1e-3", "--mass", "nan"], "mass"),
        (["--restitution", "0.5", "--contact-time", "1e-3", "--mass", "1e305"], "mass"),
        (["--restitution", "0.5", "--max-penetration", "1e-3", "--mass", "1"], "speed"),
    ],
)
def test_cli_lammps_refuses_bad_input_by_name(argv, message, capsys):
    assert main(["lammps", *argv]) == 2
    err = capsys.readouterr().err
    assert err.startswith("impactsym: error:")
    assert message in err


def test_mujoco_design_and_stick_speed_name_their_shapes():
    with pytest.raises(ValueError, match=r"restitution \(shape \(2,\)\) and speed \(shape"):
        mujoco.solref_for(restitution=[0.3, 0.5], speed=[1.0, 2.0, 3.0], solimp=FLAT)
    with pytest.raises(ValueError, match=r"restitution \(shape \(2,\)\) and contact_time"):
        mujoco.solref_for(restitution=[0.3, 0.5], speed=1.0, contact_time=[0.01] * 3, solimp=FLAT)
    with pytest.raises(ValueError, match=r"solref \(shape \(2,\)\) and inverse_weight"):
        mujoco.stick_speed(
            solref=(np.full(2, 0.02), 1.0),
            solimp=FLAT,
            gravity=9.81,
            mass=1.0,
            inverse_weight=np.ones(3),
        )
    empty = mujoco.stick_speed(solref=(np.array([]), np.array([])), solimp=FLAT, gravity=9.81)
    assert empty.shape == (0,)


def test_survey_names_its_arguments():
    from impactsym.engines import survey

    with pytest.raises(ValueError, match="targets must be <= 1"):
        survey.textbook_restitution([0.5, 2.0])
    with pytest.raises(ValueError, match="gravity must be one number"):
        survey.stick_map([0.1], [0.5], gravity=[1.0, 2.0])
    with pytest.raises(ValueError, match="dampratio must be a 1-D array"):
        survey.stick_map([0.1], [[0.5]])
    with pytest.raises(TypeError, match="speed"):
        survey.stick_map("a", [0.5])
    verdict, e = survey.stick_map(np.array([]), np.array([0.5]))
    assert verdict.shape == e.shape == (1, 0)
