"""vrdeform: XPBD deformable bodies and the haptic force signal they give, from Python.

The engine (World, materials, colliders, fingertips, attachments), meshes (read, check,
tetrahedralise), the built-in scenes and scene files, and the run loop of `vrdeform run` with a
callback per step. Positions, velocities and multipliers come as read-only NumPy views of the live
state; every error is a vrdeform.Error with the message the command-line programs print.
See docs/python.md.
"""

from ._vrdeform import *  # noqa: F401,F403
from ._vrdeform import Error, __doc__ as _native_doc  # noqa: F401

__all__ = [name for name in dir() if not name.startswith("_")]
