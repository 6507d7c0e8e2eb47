"""Warnings that point at the caller's line, however deep inside exactgeo they are raised."""

from __future__ import annotations

import os
import sys
import warnings

_PACKAGE = os.path.dirname(os.path.abspath(__file__)) + os.sep


def warn(message: str, category: type[Warning] = UserWarning) -> None:
    """warnings.warn at the first frame outside the package: the message then names the file and line of the
    code that called exactgeo, and filters keyed on that module apply, whichever of exactgeo's functions the
    call went through. A fixed stacklevel would be right for one path through the package only."""
    level = 2  # the caller of warn()
    frame = sys._getframe(1)
    while frame.f_back is not None and frame.f_code.co_filename.startswith(_PACKAGE):
        frame = frame.f_back
        level += 1
    warnings.warn(message, category, stacklevel=level)
