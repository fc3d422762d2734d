"""What every study shares: where it writes, how it writes a table, and its run options.

The run options are parsed here (:func:`add_study_options`, :func:`study_options`), for both
``mpm-fem study <name>`` and ``python studies/<name>.py`` (:func:`script_main`): a study script
never goes through the command line module.

A study writes ``figures/<name>/<table>.csv`` (one row per measurement), a ``<table>.json`` with
the exact settings, the package versions, the code version and the tier beside it, and its ``.png``
figures. The cache of finished cases lives in ``figures/<name>/.cache/`` (git-ignored).

A figures folder holds one tier (:data:`TIERS`): a command that would write a study into a folder
holding tables of another tier is refused before any case runs (:func:`check_folder`), unless
``--overwrite``, which removes those tables first; the case cache is shared between tiers (a case is
the same run in every tier).
"""

from __future__ import annotations

import argparse
import csv
import importlib
import io
import sys
from contextvars import ContextVar
from dataclasses import dataclass
from pathlib import Path

from mpm_fem.app import guard
from mpm_fem.app.output import ensure_writable_dir, versions, write_atomic, write_json
from mpm_fem.app.sweep import code_version, run_cases
from mpm_fem.measure.schema import Table
from mpm_fem.measure.tables import read_table, tiers  # noqa: F401  (read_table: the studies' and tests' reader)

#: The tiers of a reproduction: ``quick`` (the README's command, a subset of meshes), ``full`` (the
#: committed record in ``figures/``), ``deep`` (the full plan and the finest meshes and long sweeps,
#: in ``figures/deep/``).
TIERS = ("quick", "full", "deep")
#: Where each tier writes by default.
TIER_FOLDERS = {"quick": Path("figures/quick"), "full": Path("figures"), "deep": Path("figures/deep")}
#: The tier of the study being written (:func:`run_study`), stamped on every table it writes.
_WRITING: ContextVar[str | None] = ContextVar("tier", default=None)


@dataclass(frozen=True)
class StudyOptions:
    """``quick`` / ``deep``: the tier (:data:`TIERS`; neither: ``full``); ``jobs``: worker processes;
    ``scheduler``: a Dask scheduler address; ``out``: the figures folder (``figures/``);
    ``cache``: the folder whose ``<study>/.cache/`` holds the finished cases (default ``out``; the
    deep tier reads the full tier's, so that it runs only the cases the full tier has not);
    ``overwrite``: replace the tables of another tier in ``out`` (:func:`check_folder`)."""

    quick: bool = False
    jobs: int | None = None
    scheduler: str | None = None
    out: Path = Path("figures")
    progress: bool | None = None
    deep: bool = False
    cache: Path | None = None
    overwrite: bool = False

    def __post_init__(self):
        if self.quick and self.deep:
            raise ValueError("a study runs one tier: quick or deep, not both")

    @property
    def tier(self) -> str:
        """``"quick"``, ``"full"`` or ``"deep"``."""
        return "quick" if self.quick else "deep" if self.deep else "full"

    def folder(self, name: str) -> Path:
        path = Path(self.out) / name
        path.mkdir(parents=True, exist_ok=True)
        return path

    def cache_dir(self, name: str) -> Path:
        return Path(self.cache if self.cache is not None else self.out) / name / ".cache"

    def sweep(self, name: str, fn, cases: list[dict], desc: str | None = None) -> list[dict]:
        """Run ``fn`` over ``cases`` with this study's cache, workers and progress."""
        return run_cases(fn, cases, jobs=self.jobs, cache_dir=self.cache_dir(name), desc=desc or name,
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


def write_table(folder: Path, table: str | Table, rows: list[dict], settings: dict, tier: str | None = None) -> Path:
    """``<folder>/<table>.csv`` from ``rows`` (dicts with the same keys) and ``<table>.json``
    holding the ``tier`` (default: that of the study :func:`run_study` is writing; none outside it),
    ``settings``, the package versions and the code hash. Returns the CSV path. ``table`` is
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
    tier = tier or _WRITING.get()
    write_json(Path(folder) / f"{table}.json", {**({"tier": tier} if tier else {}), "settings": settings,
                                                "versions": versions(), "code": code_version()})
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


def add_tier_options(parser: argparse.ArgumentParser, default: str = "quick") -> None:
    """``--quick | --full | --deep``, into ``args.tier`` (``default`` when none is given), and
    ``--overwrite`` (replace the tables of another tier in the folder)."""
    size = parser.add_mutually_exclusive_group()
    size.add_argument("--quick", dest="tier", action="store_const", const="quick",
                      help="the quick tier, the default: a subset of meshes that judges C11 and C13, into "
                           "figures/quick (under a minute on 2 cores; reproduce leaves out the remedies, drift, "
                           "budget and defect studies there; the mechanism study runs a small stage-exact set on "
                           "the numpy step)")
    size.add_argument("--full", dest="tier", action="store_const", const="full",
                      help="every table of the committed record, figures/ (about an hour on 2 cores)")
    size.add_argument("--deep", dest="tier", action="store_const", const="deep",
                      help="the full plan and the finest meshes and long sweeps, figures/deep/ (reuses the full "
                           "tier's finished cases; hours on 2 cores, or a Dask cluster with --scheduler)")
    parser.add_argument("--overwrite", action="store_true",
                        help="a folder holds one tier: writing into a folder that holds tables of another tier is "
                             "refused unless --overwrite, which removes those tables first (the cases stay cached)")
    parser.set_defaults(tier=default)


def add_study_options(parser: argparse.ArgumentParser, quick_flag: bool = True, out_help: str | None = None) -> None:
    """The options of a study run: the tier (``--quick``, ``--full``, ``--deep``; quick by default) and
    ``--overwrite``, ``--jobs``, ``--scheduler``, ``--out``, ``--quiet``."""
    if quick_flag:
        add_tier_options(parser, "quick")
    parser.add_argument("--jobs", type=int, default=None,
                        help="worker processes, at most the number of cores (default: the cores, at most 8)")
    parser.add_argument("--scheduler", default=None,
                        help="address of a running Dask scheduler, tcp://HOST:PORT (checked with a 3 s connect)")
    parser.add_argument("--out", default=None,
                        help=out_help or "figures folder (default: figures/quick, figures or figures/deep by tier)")
    parser.add_argument("--quiet", action="store_true", help="no progress output")


def study_options(args: argparse.Namespace) -> StudyOptions:
    """:class:`StudyOptions` from parsed options; bad input raises :class:`mpm_fem.app.guard.UsageError`."""
    jobs = guard.cap_jobs(args.jobs)
    scheduler = guard.check_scheduler(args.scheduler)
    tier = args.tier
    out = args.out or TIER_FOLDERS[tier]
    # the deep tier's default folder reuses the full tier's finished cases
    cache = TIER_FOLDERS["full"] if tier == "deep" and not args.out else None
    try:
        out = ensure_writable_dir(out)
    except PermissionError as err:
        raise guard.UsageError(str(err)) from None
    return StudyOptions(quick=tier == "quick", deep=tier == "deep", jobs=jobs, scheduler=scheduler, out=out,
                        cache=cache, progress=False if args.quiet else None, overwrite=args.overwrite)


#: The studies, by name: ``studies/<name>.py``. The application loads them by name (they are the top
#: layer and import it, never the other way round).
STUDIES = ("projection", "sod", "burgers", "identification", "budget", "time", "remedies", "drift", "mechanism",
           "lumping", "defect", "plane", "plane_projection")
#: The studies the quick reproduction leaves out: their questions (E5, the mechanism of C11, E1 and the defect) are
#: about the plateau of Sod's particle error, which the quick tier's meshes reach at one setting only
#: (C11's). ``mpm-fem study NAME --quick`` still runs them. The mechanism study's small stage-exact set stays in
#: (on the numpy step, which compiles no fused exact-stage variant, only the exact grid stage's kernels of
#: :mod:`mpm_fem.exact_stages.grid_kernels`): it says which stage the error comes from.
QUICK_LEAVES_OUT = ("remedies", "drift", "budget", "defect")
_NO_BUDGET = ("the quick reproduction leaves out the error budget (its exact-stage kernels take about a minute to "
              "compile)")
#: The verdicts a tier does not judge, ``{tier: {claim: (the tier that judges it, why)}}``: the report
#: lists them (``tests/test_reproduce.py`` checks the quick tier's against its report).
NOT_JUDGED = {"quick": {
    **{c: ("full", _NO_BUDGET) for c in ("C15 (sod)", "C15 (burgers)", "E1 (sod)", "E1 (burgers)", "E2")},
    "E5": ("full", "the quick reproduction leaves out the remedies study"),
    **{c: ("full", "the quick tier's stage-exact set has two meshes and three runs a problem; the decomposition of "
               "the growth needs more of both, and the abstract quotes its orders unjudged")
       for c in ("E6a (sod)", "E6a (burgers)")},
    "E6": ("full", "the quick reproduction leaves out the defect study"),
    "E1 (control)": ("full", _NO_BUDGET),
    "E5 (jittered)": ("full", "the quick reproduction leaves out the remedies study"),
    "C11 (nodes)": ("full", "the quick identification fits Sod on two meshes, above the source's levelling"),
    **{c: ("full", "the quick plane study runs two meshes, the point mass on two layouts, the lumped and "
                   "consistent masses; these need three meshes, six layouts, the stages, FMPM or the time step")
       for c in ("D1 (axis-1e-4)", "D1 (axis-0.05)", "D1 (vortex)", "D2 (axis-0.05)", "D3", "D5",
                 "D6 (axis-1e-4)", "D6 (axis-0.05)", "D6 (vortex)", "D7")},
}}


def reproduced(tier: str) -> tuple[str, ...]:
    """The studies ``mpm-fem reproduce`` runs in ``tier``: every one of :data:`STUDIES`, but
    :data:`QUICK_LEAVES_OUT` in the quick tier."""
    return tuple(n for n in STUDIES if tier != "quick" or n not in QUICK_LEAVES_OUT)


def run_study(name: str, options: StudyOptions) -> str:
    """Run ``studies/<name>.py`` with ``options``, every table it writes stamped with ``options.tier``;
    returns the line reporting where it wrote. Checks no folder: :func:`start_study` does."""
    token = _WRITING.set(options.tier)
    try:
        importlib.import_module(f"studies.{name}").run(options)
    finally:
        _WRITING.reset(token)
    return f"study {name} written to {options.folder(name)}"


def check_folder(options: StudyOptions, studies: tuple[str, ...] | None = None) -> None:
    """Before any case runs: a folder holds one tier. If ``options.out`` holds tables of another tier
    than ``options.tier`` (an unstamped table counts as another tier), raise
    :class:`mpm_fem.app.guard.UsageError` (one line, exit status 2) and change nothing, unless
    ``options.overwrite``: then remove those tables (CSV and JSON) of the study folders ``studies``
    (``None``: every one) and keep the cached cases."""
    other = {table: tier for table, tier in tiers(options.out).items() if tier != options.tier}
    if not other:
        return
    if not options.overwrite:
        found = sorted(set(other.values()))
        raise guard.UsageError(
            f"{options.out} holds {len(other)} tables of the {' and '.join(found)} tier (e.g. {next(iter(other))}), "
            f"and a folder holds one tier: the {options.tier} tier is not written there; pass --overwrite to "
            "replace them, or --out another folder")
    for table in other:
        if studies is None or table.split("/")[0] in studies:
            for suffix in (".csv", ".json"):
                (Path(options.out) / f"{table}{suffix}").unlink(missing_ok=True)


def start_study(name: str, options: StudyOptions) -> str:
    """``mpm-fem study <name>``: check the folder (:func:`check_folder`), print the estimate (unless
    ``options.progress`` is ``False``), then :func:`run_study`."""
    from mpm_fem.app.case_tasks import estimate
    from mpm_fem.app.estimate import describe
    from mpm_fem.app.sweep import default_jobs

    check_folder(options, (name,))
    if options.progress is not False:
        print(describe({name: estimate(name, options)}, options.jobs or default_jobs()), file=sys.stderr, flush=True)
    return run_study(name, options)


def script_main(name: str, argv=None) -> int:
    """Entry point of ``python studies/<name>.py``: the same options, errors and exit statuses as
    ``mpm-fem study <name>``."""
    parser = guard.OneLineParser(prog=f"studies/{name}.py", description=f"Run the {name} study.")
    add_study_options(parser)
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)

    def command():
        line = start_study(name, study_options(args))
        if not args.quiet:
            print(line)

    return guard.exit_status(f"studies/{name}.py", command)
