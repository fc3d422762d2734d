"""What every benchmark script shares: the ``--markdown FILE`` option and the block it writes.

A benchmark prints its tables; with ``--markdown FILE`` the same text also replaces the script's
generated block in ``FILE`` (``docs/performance.md``), headed by the date, the machine and the
command that measured it (:func:`mpm_fem.app.output.tee_markdown`).
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import sys

from mpm_fem.app.output import tee_markdown


def add_markdown_option(parser: argparse.ArgumentParser) -> None:
    """``--markdown FILE``: also write the tables into FILE's generated block."""
    parser.add_argument("--markdown", metavar="FILE", default=None,
                        help="also write the tables into FILE's generated block (docs/performance.md)")


def measured_block(markdown: str | None, script: str, block: str | None = None):
    """The context in which a benchmark prints its tables: ``tee_markdown`` into ``markdown``'s block
    ``block`` (default: named after ``script``, ``"step_cost"`` for ``benchmarks/step_cost.py``), headed by
    today's date, the command (the script and its arguments but ``--markdown``), the machine's name and its
    core count."""
    today = datetime.date.today().isoformat()
    command = " ".join([f"python benchmarks/{script}.py", *_arguments(sys.argv[1:])])
    header = f"Measured on {today} by `{command}` ({platform.node()}, {os.cpu_count()} cores)."
    return tee_markdown(markdown, block or script, header)


def _arguments(argv: list[str]) -> list[str]:
    """``argv`` without ``--markdown FILE`` (or ``--markdown=FILE``): where it is written is not how it was
    measured."""
    out, skip = [], False
    for arg in argv:
        if skip:
            skip = False
        elif arg == "--markdown":
            skip = True
        elif not arg.startswith("--markdown="):
            out.append(arg)
    return out
