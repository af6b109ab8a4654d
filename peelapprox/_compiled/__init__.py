"""The compiled machinery below the law: the kernel compiler and its private cache, the one integrator, and
the one symbolic/codegen pipeline.

``_jit`` (every kernel goes through ``kernel``/``jitable``; ``KERNEL_SOURCES``), ``_kcache`` and
``_private`` (numba's cache in a private root, every file checked), ``_dop853`` with its coefficients
``_dop853_tableau``, the model's sympy source ``_symbolic``, the one renderer ``_render`` (the model's
kernels and every law), the model's generated kernels ``_generated`` (``python -m peelapprox.law.codegen``)
and their compiled forms ``_model_jit``.  Imports nothing of the law or of the rooms above it; the
door through which ``exact`` gets these pieces is ``peelapprox.kernels``.
"""
