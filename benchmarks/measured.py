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

from mpm_fem.app.output import tee_markdown


def add_markdown_option(parser: argparse.ArgumentParser) -> None:
    """``--markdown FILE``: also write the tables into FILE's generated block."""
    parser.add_argument("--markdown", metavar="FILE", default=None,
                        help="also write the tables into FILE's generated block (docs/performance.md)")


def measured_block(markdown: str | None, script: str):
    """The context in which a benchmark prints its tables: ``tee_markdown`` into ``markdown``'s block
    named after ``script`` (``"step_cost"`` for ``benchmarks/step_cost.py``), headed by today's date,
    the machine's name and its core count."""
    today = datetime.date.today().isoformat()
    header = f"Measured on {today} by `python benchmarks/{script}.py` ({platform.node()}, {os.cpu_count()} cores)."
    return tee_markdown(markdown, script, header)
