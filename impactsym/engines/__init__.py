"""What the contact theory means for simulation engines (MuJoCo, LAMMPS).

:mod:`impactsym.engines.mujoco` predicts and designs MuJoCo's ``solref``/``solimp``;
:mod:`impactsym.engines.lammps` the Hooke spring-dashpot of LAMMPS ``pair_style
granular``; both solve the loaded section-2 oscillator with
:mod:`impactsym.contact.release`, and :mod:`impactsym.engines.derivation` is the SymPy
derivation of MuJoCo's contact equation. None of them imports an engine: the engines
(``pip install impactsym[engines]``) are needed only to check the predictions.
Submodules are imported on demand.
"""
