"""What the contact theory means for simulation engines (MuJoCo, LAMMPS, Drake, PyBullet).

:mod:`impactsym.engines.mujoco` predicts and designs MuJoCo's ``solref``/``solimp``
(``model``: the engine's contact law; ``prediction``; ``design``);
:mod:`impactsym.engines.lammps` the Hooke spring-dashpot of LAMMPS ``pair_style
granular``; both solve the loaded section-2 oscillator with
:mod:`impactsym.contact.release`, and both model the engine's own step at the user's
timestep (the touch phase). :mod:`impactsym.engines.drake` does the same for Drake's
point contact (Hunt–Crossley, continuous and each discrete approximation) and
:mod:`impactsym.engines.pybullet` for PyBullet's ``contactStiffness``/``contactDamping``
(the ERP/CFM contact row); their drivers live in their packages.
:mod:`impactsym.engines.derivation` is the SymPy
derivation of MuJoCo's contact equation, the reference of ``mujoco.model``, and
:mod:`impactsym.engines.survey` compares the textbook design with both engines. None of
them imports an engine: the engines (``pip install impactsym[engines]``) are needed only by
:mod:`impactsym.engines.drivers`, which runs them to check the predictions
(`docs/physics.md#simulation-engines`). Submodules are imported on demand.
"""
