"""Rigid-folding checks shared by the Miura and TMP generator tests."""

import numpy as np


def panel_errors(p):
    """Max relative panel-edge length change vs the flat layout and max quad non-planarity."""
    flat = np.column_stack([p.flat, np.zeros(len(p.flat))])
    len_err, plan_err = 0.0, 0.0
    for f in p.faces:
        P, Q = p.coords[f], flat[f]
        d3 = np.linalg.norm(np.roll(P, -1, 0) - P, axis=1)
        d2 = np.linalg.norm(np.roll(Q, -1, 0) - Q, axis=1)
        len_err = max(len_err, float(np.max(np.abs(d3 - d2) / d2)))
        if len(f) == 4:
            nrm = np.cross(P[1] - P[0], P[2] - P[0])
            nrm /= np.linalg.norm(nrm)
            plan_err = max(
                plan_err, abs(float(np.dot(P[3] - P[0], nrm))) / np.linalg.norm(P[2] - P[0])
            )
    return len_err, plan_err
