"""What the criteria found, judged once and said in words: the findings of every claim (:func:`judge`),
the verdict cell (:func:`verdict_text`: the verdict word, or for ``partly`` the count of cases it holds
on, :func:`counted`), the summary's key number (:func:`key_text`) and a finding in one sentence
(:func:`said`); and the small word helpers the sections share (a list joined with "and", a finding's
first clause, a range of numbers as prose writes it).

``Found`` is ``{label: (claim, finding)}``: :func:`judge` computes every finding once and every section
takes its result, so that a report renders each criterion once.
"""

from __future__ import annotations

import math
import re
from dataclasses import replace

from mpm_fem.app.markdown import anchor_of, readable, split_outside
from mpm_fem.measure.claims import CLAIMS, Claim, Finding, failures
from mpm_fem.measure.claims.base import CONFIRMED, NOT_MEASURED, PARTLY, VERDICTS
from mpm_fem.measure.tables import Tables

Found = dict[str, tuple[Claim, Finding]]


def judge(tables: Tables, left_out: dict[str, str] | None = None) -> Found:
    """Every registered claim's finding on ``tables``, by label, in the order of :data:`CLAIMS`; a finding
    that names no failed run while a table its claim reads holds some gets them named
    (:func:`mpm_fem.measure.claims.failures`), so that no failed run is left out silently. A claim that
    reads a table of ``left_out`` (``{table: its code version}``: another version than the record's,
    :func:`mpm_fem.app.report.of_code`) is not measured, and says why."""
    left_out = left_out or {}
    found = {}
    for c in CLAIMS:
        left = [name for name in c.tables if name in left_out]
        f = (Finding(NOT_MEASURED, "left out: " + ", ".join(f"`{name}.csv` was written by code version "
                                                             f"{left_out[name]}" for name in left)
                     + ", another than the record's") if left else _with_failures(c, c.finding(tables), tables))
        found[c.label] = (c, f)
    return found


def _with_failures(c: Claim, f: Finding, tables: Tables) -> Finding:
    if f.failed:
        return f
    lines = tuple(line for name in c.tables for line in failures(tables.get(name) or [], ("h",), name))
    return replace(f, failed=lines) if lines else f


def first_clause(f: Finding) -> str:
    """The evidence's first clause, whole: the key number of the summary when there is no sentence."""
    return split_outside(f.evidence)[0].rstrip(".") if f.evidence.strip() else ""


#: The longest key number of the README's verdict table, in characters
KEY_CHARS = 120


def key_text(f: Finding, brief: bool = False) -> str:
    """The summary's key number: the finding's sentence, or its evidence's first clause; ``brief``: the
    first of its short forms (:attr:`~mpm_fem.measure.claims.base.Finding.key`) that fits
    :data:`KEY_CHARS` as printed, else its tersest (the README's)."""
    text = readable(f.sentence.strip() or first_clause(f))
    if not brief or len(text) <= KEY_CHARS or not f.key:
        return text
    forms = [readable(k.strip()) for k in f.key]
    return next((k for k in forms if len(k) <= KEY_CHARS), forms[-1])


_TRUE, _FALSE = ("true", "yes", "1"), ("false", "no", "0")


_COUNTED = re.compile(r"\bon (\d+) of (\d+) ([a-z][a-z -]*[a-z])")


#: The verdict cell of a claim that holds on some of its cases: the count, the verdict's meaning in numbers.
COUNT_MEANING = ("holds on k of n", "partly, counted: the statement holds on k of the n cases (settings, layouts, "
                 "meshes, fits) the evidence names, and on no other")


def _plural(noun: str) -> str:
    noun = noun.strip().lower()
    return noun[:-1] + "ies" if noun.endswith("y") else noun if noun.endswith("s") else noun + "s"


def counted(f: Finding) -> str:
    """How many of a finding's cases the statement holds on, ``"holds on 3 of 4 layouts"``: from its table's
    ``holds`` column (or its first yes/no column, or its ``verdict`` column), else from an ``on k of n
    <cases>`` of its evidence's first clause (the key number), its sentence or its evidence; "" when it
    states no count. A table's count of none or all, which alone would not make the verdict partial, is
    joined by the first other count of the evidence (the claim's other part: ``"holds on 0 of 4 settings
    and 21 of 26 remedies"``)."""
    rows = list(f.table)
    if rows:
        columns = list(rows[0])
        flags = [c for c in columns if c == "holds"] + [
            c for c in columns[1:] if all(str(r.get(c, "")).strip().lower() in _TRUE + _FALSE for r in rows)]
        if flags:
            hits = sum(str(r.get(flags[0], "")).strip().lower() in _TRUE for r in rows)
            cases = _plural(columns[0])
            other = [m for m in _COUNTED.finditer(f.evidence or "") if m.group(3) != cases] \
                if hits in (0, len(rows)) else []
            more = f" and {other[0].group(1)} of {other[0].group(2)} {other[0].group(3)}" if other else ""
            return f"holds on {hits} of {len(rows)} {cases}{more}"
        if "verdict" in columns:
            judged = [r for r in rows if r.get("verdict") in VERDICTS and r.get("verdict") != NOT_MEASURED]
            if judged:
                hits = sum(r.get("verdict") == CONFIRMED for r in judged)
                return f"holds on {hits} of {len(judged)} {_plural(columns[0])}"
    key = (f.evidence or "").split(";")[0]  # the evidence's first clause holds the key number
    for text in (key, f.sentence, f.evidence):
        m = _COUNTED.search(text or "")
        if m:
            return f"holds on {m.group(1)} of {m.group(2)} {m.group(3)}"
    return ""


def verdict_text(f: Finding) -> str:
    """The verdict cell: the verdict word, or for ``partly`` its count where the finding states one
    (:func:`counted`)."""
    return (counted(f) or f.verdict) if f.verdict == PARTLY else f.verdict


#: The files of the report: the main text and its appendices.
REPORT_FILE, APPENDIX_FILE = "REPORT.md", "APPENDIX.md"
#: The studies whose claims are said in the appendix's further results rather than in the results (the
#: main text's summary still gives their verdicts and key numbers): the main text stays a paper's length.
IN_APPENDIX = ("lumping", "defect")


def claim_href(c: Claim, here: str | None = REPORT_FILE, folder: str = "") -> str:
    """The link target of a claim's section, from the file ``here`` (``None``: from outside the folder,
    through ``folder``, e.g. ``"figures/"``): ``#c5`` in its own file, else ``APPENDIX.md#e7-sod``; the
    claims of :data:`IN_APPENDIX` are said in the appendix, the others in the report."""
    file = APPENDIX_FILE if c.study in IN_APPENDIX else REPORT_FILE
    return f"#{anchor_of(c.label)}" if file == here else f"{folder}{file}#{anchor_of(c.label)}"


def labelled(text: str, label: str) -> str:
    """``text (label)``; a text ending in a parenthesis takes the label inside it, ``(mean orders ...; C11)``,
    not two parentheses in a row."""
    return f"{text[:-1]}; {label})" if text.endswith(")") and "(" in text else f"{text} ({label})"


def said(c: Claim, f: Finding, link: bool = False) -> str:
    """The finding in one sentence with the claim's label (a link to its section when ``link``): its
    plain sentence, or the statement and the evidence's first clause."""
    label = f"[{c.label}]({claim_href(c)})" if link else c.label
    if f.sentence:
        text = readable(f.sentence.strip().rstrip("."))
        return labelled(f"{text[:1].upper()}{text[1:]}", label) + "."
    statement = c.statement[0].upper() + c.statement[1:]
    return f"{statement} ({label}): {readable(first_clause(f))}."


def _and(items: list) -> str:
    """``[a, b, c]`` -> ``"a, b and c"``."""
    items = [str(i) for i in items]
    return ", ".join(items[:-1]) + " and " + items[-1] if len(items) > 1 else "".join(items)


def _clause(f: Finding) -> str:
    """The finding's sentence (or evidence) up to its first semicolon, its numbers as prose writes them."""
    text = f.sentence.strip() or f.evidence.strip()
    return readable(split_outside(text)[0].rstrip(".")) if text else ""


def _lower(text: str) -> str:
    return text[:1].lower() + text[1:] if text[1:2].islower() or text[1:2] == " " else text


def _number(text: str) -> float:
    try:
        return float(str(text).strip().lstrip("x"))
    except ValueError:
        return math.nan


def _range(values) -> str:
    v = [x for x in values if math.isfinite(x)]
    if not v:
        return ""
    lo, hi = readable(f"{min(v):.2g}"), readable(f"{max(v):.2g}")
    return lo if lo == hi else f"{lo} to {hi}"
