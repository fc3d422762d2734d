"""One module per study. Each defines

    run(options: mpm_fem.study.StudyOptions) -> None   # computes, writes figures/<name>/ tables + PNGs
    report(folder: pathlib.Path) -> str                # Markdown section of figures/REPORT.md, read
                                                       # from the written tables (claims, verdicts)
    claims(folder: pathlib.Path) -> list[dict]         # optional: [{"id": "C5", "verdict": "confirmed",
                                                       #   "evidence": "one line with the numbers"}]

and ends with ``if __name__ == "__main__": sys.exit(script_main("<name>"))`` so that
``python studies/<name>.py [--quick] [--jobs N]`` and ``mpm-fem study <name>`` are the same.
"""

STUDIES = ("projection", "sod", "burgers", "budget", "remedies")
