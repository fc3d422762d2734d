"""What every study shares: where it writes, how it writes a table, and its run options.

The run options are parsed here (:func:`add_study_options`, :func:`study_options`), for both
``mpm-fem study <name>`` and ``python studies/<name>.py`` (:func:`script_main`): a study script
never goes through the command line module.

A study writes ``figures/<name>/<table>.csv`` (one row per measurement), a ``<table>.json`` with
the exact settings and the package versions beside it, and its ``.png`` figures. The cache of
finished cases lives in ``figures/<name>/.cache/`` (git-ignored).
"""

from __future__ import annotations

import argparse
import csv
import importlib
import io
import sys
from dataclasses import dataclass
from pathlib import Path

from mpm_fem.app import guard
from mpm_fem.app.output import ensure_writable_dir, versions, write_atomic, write_json
from mpm_fem.app.sweep import code_version, run_cases
from mpm_fem.measure.schema import Table
from mpm_fem.measure.tables import read_table  # noqa: F401  (re-exported: the studies' and tests' reader)


@dataclass(frozen=True)
class StudyOptions:
    """``quick``: the subset of meshes the README's default run uses; ``jobs``: worker processes;
    ``scheduler``: a Dask scheduler address; ``out``: the figures folder (``figures/``)."""

    quick: bool = False
    jobs: int | None = None
    scheduler: str | None = None
    out: Path = Path("figures")
    progress: bool | None = None

    def folder(self, name: str) -> Path:
        path = Path(self.out) / name
        path.mkdir(parents=True, exist_ok=True)
        return path

    def sweep(self, name: str, fn, cases: list[dict], desc: str | None = None) -> list[dict]:
        """Run ``fn`` over ``cases`` with this study's cache, workers and progress."""
        return run_cases(fn, cases, jobs=self.jobs, cache_dir=self.folder(name) / ".cache", desc=desc or name,
                         scheduler=self.scheduler, progress=self.progress)

    def sweep_plan(self, name: str, fn, plan: dict[str, dict], cost=None) -> dict[str, dict]:
        """Run a plan, ``{group: {label: case}}``, in one sweep: a case shared by several groups runs
        once, the most costly first (``cost(case)``); returns ``{group: {label: result}}``."""
        key = lambda case: repr(sorted(case.items()))  # noqa: E731
        unique = {}
        for group in plan.values():
            for case in group.values():
                unique.setdefault(key(case), case)
        cases = sorted(unique.values(), key=cost, reverse=True) if cost else list(unique.values())
        results = dict(zip(map(key, cases), self.sweep(name, fn, cases), strict=False))
        return {g: {label: results[key(c)] for label, c in group.items()} for g, group in plan.items()}


def write_table(folder: Path, table: str | Table, rows: list[dict], settings: dict) -> Path:
    """``<folder>/<table>.csv`` from ``rows`` (dicts with the same keys) and ``<table>.json``
    holding ``settings``, the package versions and the code hash. Returns the CSV path. ``table`` is
    the file's name, or a table declared in :mod:`mpm_fem.measure.schema`: then the rows' columns
    must be the declared ones (:class:`mpm_fem.measure.schema.ColumnsError` otherwise, nothing written)."""
    if not rows:
        raise ValueError(f"table {table!r} has no rows")
    if isinstance(table, Table):
        table.check(rows)
        table = table.stem
    columns = list(rows[0])
    for row in rows[1:]:
        columns += [c for c in row if c not in columns]
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=columns, lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: _fmt(v) for k, v in row.items()})
    path = Path(folder) / f"{table}.csv"
    write_atomic(path, buffer.getvalue())
    write_json(Path(folder) / f"{table}.json", {"settings": settings, "versions": versions(), "code": code_version()})
    return path


def publish(folder: Path, tables: dict[str | Table, list[dict]], settings: dict, extra: dict | None = None,
            figures=()) -> None:
    """Write every non-empty table of ``tables`` (``{name: rows}``, the name a string or a table
    declared in :mod:`mpm_fem.measure.schema`) with ``settings`` (and the ``extra`` settings of that
    table, keyed by file name), then draw the ``figures`` (:class:`mpm_fem.app.plots.Plot`) whose
    table was written. The declared tables' columns are checked before any table is written."""
    from mpm_fem.app import plots

    for table, rows in tables.items():
        if rows and isinstance(table, Table):
            table.check(rows)
    named = {_stem(table): rows for table, rows in tables.items()}
    for table, rows in tables.items():
        if rows:
            write_table(folder, table, rows, {**settings, **(extra or {}).get(_stem(table), {})})
    for plot in figures:
        if named.get(plot.table):
            plots.draw(folder, plot, named[plot.table])


def _stem(table: str | Table) -> str:
    return table.stem if isinstance(table, Table) else table


def _fmt(value):
    if isinstance(value, float):
        return f"{value:.6g}"
    return value


def add_study_options(parser: argparse.ArgumentParser, quick_flag: bool = True, out_help: str | None = None) -> None:
    """The options of a study run: ``--quick``, ``--jobs``, ``--scheduler``, ``--out``, ``--quiet``."""
    if quick_flag:
        parser.add_argument("--quick", action="store_true", help="the subset of meshes of the quick reproduction")
    parser.add_argument("--jobs", type=int, default=None,
                        help="worker processes, at most the number of cores (default: the cores, at most 8)")
    parser.add_argument("--scheduler", default=None,
                        help="address of a running Dask scheduler, tcp://HOST:PORT (checked with a 3 s connect)")
    parser.add_argument("--out", default=None,
                        help=out_help or "figures folder (default: figures, or figures/quick with --quick)")
    parser.add_argument("--quiet", action="store_true", help="no progress output")


def study_options(args: argparse.Namespace) -> StudyOptions:
    """:class:`StudyOptions` from parsed options; bad input raises :class:`mpm_fem.app.guard.UsageError`."""
    jobs = guard.cap_jobs(args.jobs)
    scheduler = guard.check_scheduler(args.scheduler)
    out = args.out or ("figures/quick" if args.quick else "figures")
    try:
        out = ensure_writable_dir(out)
    except PermissionError as err:
        raise guard.UsageError(str(err)) from None
    return StudyOptions(quick=args.quick, jobs=jobs, scheduler=scheduler, out=out,
                        progress=False if args.quiet else None)


#: The studies, by name: ``studies/<name>.py``. The application loads them by name (they are the top
#: layer and import it, never the other way round).
STUDIES = ("projection", "sod", "burgers", "budget", "time", "remedies")


def run_study(name: str, options: StudyOptions) -> str:
    """Run ``studies/<name>.py`` with ``options``; returns the line reporting where it wrote."""
    importlib.import_module(f"studies.{name}").run(options)
    return f"study {name} written to {options.folder(name)}"


def script_main(name: str, argv=None) -> int:
    """Entry point of ``python studies/<name>.py``: the same options, errors and exit statuses as
    ``mpm-fem study <name>``."""
    parser = guard.OneLineParser(prog=f"studies/{name}.py", description=f"Run the {name} study.")
    add_study_options(parser)
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)

    def command():
        line = run_study(name, study_options(args))
        if not args.quiet:
            print(line)

    return guard.exit_status(f"studies/{name}.py", command)
