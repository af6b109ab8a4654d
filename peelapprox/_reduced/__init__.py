"""The paper's reduced branch-wise equations (Sec. V) and the attractor they predict.

The α equations ``_alpha`` (Airy, Airy1, Airy2, approxalpha), one branch stay ``_segment`` (the lean path a chain
of stays takes: ``_segment_plan``) with its compiled driver ``_segment_kernel``, the reduced return map
``_reducedmap`` (its compiled returns in ``_reducedmap_kernel``), the approximate attractor ``_approximate`` (what
one start of the map reaches: ``_approx_start``) and its result ``_approx_result``, the regime estimates
``_estimate``, their labels ``_regime`` and the measured validity ``_validity``.
"""
