"""One line to stderr in one write.

The forked AGV processes of a host share its stderr pipe; ``print`` may write a
line's text and its newline separately, and two processes then interleave them
into garbled lines. A single ``os.write`` of a line below PIPE_BUF (4 KiB) is atomic.
"""

from __future__ import annotations

import os
import sys


def say(line: str) -> None:
    """Write ``line`` and a newline to stderr at once (flushing what Python buffered)."""
    sys.stderr.flush()
    os.write(sys.stderr.fileno(), (line + "\n").encode(errors="replace"))
