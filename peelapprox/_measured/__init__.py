"""A measured force trace: ``_series`` (``ForceSeries``) and its Lyapunov exponent ``_series_lyapunov`` (its
divergence curve in ``_divergence``).

Its slip detector (``peelapprox/_slips.py``, ``_slips_knee.py``) stays on the ground floor: the law's
smoothing reads its noise estimate too, and the law may not import a room that builds on it.
"""
