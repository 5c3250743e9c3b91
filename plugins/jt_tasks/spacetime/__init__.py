"""``task=spacetime``: learning motor skills with spacetime bounds (``002``, Ma et al. 2021)."""
