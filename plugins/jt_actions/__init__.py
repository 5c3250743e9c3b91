"""jt's built-in action spaces (``jt.actions``): raw PD targets, P-VAE, C-VAE, FFC + FBC.

See docs/priors.md. Modules import numpy and the toolkit's light parts only at import time.
"""
