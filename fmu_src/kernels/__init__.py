"""The kernel language and the tools that read it.

- ``kernel_language``: the calls a kernel may make (its table) and the analysis the translator
  and the tangent generator share;
- ``unrolling``: tuples and sums over a constant range written out;
- ``python_to_c``: a kernel translated to C;
- ``tangents``: derivatives generated from the kernels; ``vector_tangents``: the same in many
  directions at once, for the fit;
- ``generated_source``: the check that a generated module binds every name it reads;
- ``numba_binding``: the kernels compiled with numba, cached on disk; ``jit``: numba or its
  plain-Python stand-in.

May import: ``..model``; never ``..models`` by name (a model is passed in).
"""
