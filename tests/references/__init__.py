"""Independent references shared by the tests and benchmarks (never imported by the package).

Nothing here is derived from impactsym: each module solves the paper's problems another way.

* :mod:`references.oscillator` -- the spring-damper contact of section 2 by the 40-digit
  mpmath matrix exponential and bracketed root refinement.
* :mod:`references.rod_characteristics` -- the rigid rod impact of section 1 by
  d'Alembert's solution and a neutral delay equation (Chebyshev collocation).
* :mod:`references.rod_elastic_delay` -- the rod impact with a finite contact stiffness
  by d'Alembert's solution and a delay ODE (method of steps, SciPy DOP853).
* :mod:`references.multibody_systems` -- the section-3 test systems written with
  ``sympy.physics.mechanics`` and their full nonlinear simulation with SciPy.
* :mod:`references.bounce` -- the bounce sequence until rest by an event-driven SciPy
  simulation of contacts and flights.
* :mod:`references.engines` -- the real engines driven directly (a MuJoCo drop on a
  plane, a LAMMPS wall impact), for the engine tests, notebook 04 and the benchmark.
* :mod:`references.paper` -- formulas typed in from the paper (eq. (2)).
"""
