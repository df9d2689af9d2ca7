"""numba options shared by the compiled modules of :mod:`holofold.mechanics`.

``OPTS``: cached on disk, no GIL, numpy's error model (no exceptions from arithmetic), no
bounds checks. ``NOALIAS``: the same, and LLVM may assume that no two array arguments
overlap, which is what lets the spring loop (:mod:`~holofold.mechanics._spring_loop`)
vectorise; functions compiled with it must never be given overlapping output arrays.
"""

from __future__ import annotations

import llvmlite.binding as llvm
from numba.core.compiler import Compiler

__all__ = ["OPTS", "NOALIAS"]

OPTS = dict(cache=True, nogil=True, error_model="numpy", boundscheck=False)


class _NoAliasCompiler(Compiler):
    """numba's compiler with ``noalias`` on the array arguments."""

    def define_pipelines(self):
        self.state.flags.noalias = True
        return super().define_pipelines()


NOALIAS = dict(OPTS, pipeline_class=_NoAliasCompiler)

# The spring loop writes some hundred output rows whose strides are run-time values; LLVM
# checks at run time that they do not overlap the inputs, and its default limits on the
# number of such checks (8 and 128) would leave the loop scalar. These process-wide options
# only allow the vectoriser to emit more checks; they change no result.
for _opt in ("-runtime-memory-check-threshold=4096", "-vectorize-memory-check-threshold=4096"):
    llvm.set_option("holofold", _opt)
