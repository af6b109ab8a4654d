"""The paper's reduced branch-wise equations (Sec. V) and the attractor they predict.

The α equations ``_alpha`` (Airy, Airy1, Airy2, approxalpha), one branch stay ``_segment`` with its compiled
driver ``_segment_kernel``, the reduced return map ``_reducedmap`` (its compiled returns in
``_reducedmap_kernel``), the approximate attractor
``_approximate`` and its result ``_approx_result``, the regime estimates ``_estimate``, their labels
``_regime`` and the measured validity ``_validity``.
"""
