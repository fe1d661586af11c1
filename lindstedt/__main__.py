"""``python -m lindstedt``: the ``lindstedt`` command (:func:`lindstedt.cli.main`)."""

import contextlib
import os
import sys

from .cli import EXIT_INTERRUPTED, main

status = main()
if status == EXIT_INTERRUPTED:
    # Under ``-m`` CPython (3.11, 3.12) exits by SIGINT (status -2) after finalizing when a KeyboardInterrupt once
    # ended code run from a string (a dataclass's generated __init__, a namedtuple), even one caught and handled:
    # the command's status, 130, is given here, once the streams are flushed.
    with contextlib.suppress(OSError, ValueError):
        sys.stdout.flush()
        sys.stderr.flush()
    os._exit(status)
sys.exit(status)
