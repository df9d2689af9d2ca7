"""Nonlinear static solvers (each returns a path and a status)."""
