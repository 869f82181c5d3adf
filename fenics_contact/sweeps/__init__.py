"""Sweeps over methods and parameters: the paper's study, speed against accuracy, stability."""
