"""Simulated boards of either firmware generation, so that every example and test runs on a
laptop.

``pty()`` serves one in real time on a pseudo-terminal (Unix): open its ``path`` as the board's
serial port. ``Board`` is one in this process, with no clock of its own.
"""

from .chassis_native import Board, Pty, pty

__all__ = ["Board", "Pty", "pty"]
