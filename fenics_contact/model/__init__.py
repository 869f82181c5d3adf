"""Physics: materials, rigid obstacles, contact terms and the problem's UFL systems.

Imports nothing from the rest of the package; solvers, scenes and output
build on it.
"""
