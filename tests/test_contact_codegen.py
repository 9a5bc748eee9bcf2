"""The section-2 pieces of the exported module (:mod:`impactsym.contact.codegen`): every
form the kernel evaluates is exported, as the same code."""

from __future__ import annotations

import dataclasses
import re
from functools import partial

import numpy as np

from impactsym.contact import kernel
from impactsym.contact.codegen import CONTACT_EXPORTS, contact_items, form_pieces
from impactsym.numeric.codegen import broadcast_evaluate
from impactsym.numeric.pysource import collect


def test_every_kernel_form_is_exported_and_computes_the_same_floats():
    namespace = {"np": np, "partial": partial, "broadcast_evaluate": broadcast_evaluate}
    exec("from __future__ import annotations\n\n" + "\n\n".join(form_pieces()), namespace)
    forms = namespace["FORMS"]
    pieces = [
        getattr(kernel.kernels(condition=c), field.name)
        for c in ("position", "force")
        for field in dataclasses.fields(kernel.Kernels)
    ] + [kernel.z_dot()]
    assert sorted(forms) == sorted(p.name for p in pieces)
    rng = np.random.default_rng(7)
    for piece in pieces:
        assert set(forms[piece.name]) == set(piece.functions)  # the same regimes
        for regime, package in piece.functions.items():
            n = 300
            D = {"underdamped": rng.uniform(0, 1, n), "critical": np.ones(n)}.get(
                regime, rng.uniform(1, 50, n)
            )
            values = [rng.uniform(0, 10, n)] if piece.d_index else []
            values += [D, rng.uniform(0, 3, n)]
            args = [*values, *kernel._aux(regime, D)]
            exported = namespace["broadcast_evaluate"](forms[piece.name][regime], *args)
            assert np.array_equal(exported, package(*args), equal_nan=True), (piece.name, regime)


def test_the_section2_pieces_define_every_exported_name():
    source = "\n\n".join(collect(contact_items()))
    for name in CONTACT_EXPORTS:
        assert f"def {name}(" in source or re.search(rf"^class {name}[:(]", source, re.M), name
