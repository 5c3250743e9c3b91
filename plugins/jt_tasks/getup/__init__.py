"""``task=getup``: get-up motions that track style curves (Frezzato et al. 2022, ``003``; docs/getup.md).

``features``: the style features (h, θx, θz) and the heading frame of any simulated state;
``curves``: the feature curves (cubic B-splines, 9 control points, eq 1); ``initial``: fallen
states from a passive ragdoll and the clips' first poses; ``env``: ``GetupEnv`` (``CharacterEnv``);
``task``: ``GetupTask`` (``PolicyTask``).
"""
