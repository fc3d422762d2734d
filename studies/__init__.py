"""One module per study. Each holds only what is particular to it:

    its plan                 the cases, as dicts (``_plan``), run in one sweep with a cache
    run_case(case) -> dict   how one case becomes a result (in a worker process)
    run(options) -> None     the tables it writes from the results (``mpm_fem.app.study.publish``)
    PLOTS                    its figures, each with a one-line caption, drawn from its tables

and ends with ``if __name__ == "__main__": sys.exit(script_main("<name>"))`` so that
``python studies/<name>.py [--quick] [--jobs N]`` and ``mpm-fem study <name>`` are the same. The
verdicts on the claims are computed from the tables by :mod:`mpm_fem.measure.claims`, and the report is
rendered by :mod:`mpm_fem.app.report`; no study writes Markdown or decides a verdict.
"""

from mpm_fem.app.study import STUDIES  # noqa: F401  (the registry lives in the application layer)
