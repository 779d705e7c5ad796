import os
import pathlib

import numpy as np
import pytest

import vrdeform


@pytest.fixture
def cube():
    """A 1 cm cube of five tets: its corners and one centre-cut split."""
    v = np.array([[x, y, z] for x in (0, 0.01) for y in (0, 0.01) for z in (0, 0.01)], dtype=np.float32)
    # Corners i = 4x + 2y + z; five positively oriented tets.
    tets = [[0, 1, 2, 4], [3, 2, 1, 7], [5, 1, 4, 7], [6, 4, 2, 7], [1, 2, 4, 7]]
    fixed = []
    for t in tets:
        a, b, c, d = (v[i] for i in t)
        fixed.append(t if np.dot(b - a, np.cross(c - a, d - a)) > 0 else [t[0], t[2], t[1], t[3]])
    return vrdeform.TetMesh(v, fixed)


@pytest.fixture
def cli():
    path = os.environ.get("VRDEFORM_CLI")
    if not path:
        pytest.skip("VRDEFORM_CLI (the vrdeform program) not set: run through ctest")
    return pathlib.Path(path)
