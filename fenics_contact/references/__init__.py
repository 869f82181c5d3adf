"""Analytic references for users' checks: Hertz (2D, 3D), Cattaneo-Mindlin, and the measurements.

Each module compares a converged problem with a closed-form answer at the
problem's own load: :mod:`.hertz` and :mod:`.hertz3d` the formulas,
:mod:`.measure` the Hertz comparison of a contact state, :mod:`.cattaneo`
the Cattaneo-Mindlin stick zone and traction.
"""
