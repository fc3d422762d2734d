"""The report's body as a paper: abstract, introduction, method, results, discussion, conclusions.

Every sentence is a template filled from the tables and from what the criteria found
(:meth:`mpm_fem.measure.claims.Claim.finding`): a :class:`~mpm_fem.measure.claims.Finding`'s plain
``sentence`` where the criterion writes one, its small evidence ``table`` where it has one. A finding
without a sentence is said by its evidence's first clause, whole; one without a table shows its
evidence as a list cut at its semicolons. No verdict string is pasted into the abstract or the
conclusions, no key number is cut, and no paragraph passes :data:`mpm_fem.app.markdown.MAX_WORDS`.

One module per part: :mod:`.paper_findings` (the findings, judged once, and the verdict cell),
:mod:`.paper_abstract` (the first screen: abstract and introduction), :mod:`.paper_method` (the
method, the terms, the settings and the rule book), :mod:`.paper_results` (the results and each
claim's evidence) and :mod:`.paper_discussion` (the discussion and the conclusions). This module
numbers the sections (:func:`numbered`) and gives their names in one place, as the report reads them.

:func:`judge` computes every finding once; the sections take its result (``found``: ``{label:
(claim, finding)}``), so that a report renders each criterion once.
"""

from __future__ import annotations

from mpm_fem.app.discussion import defect_section  # noqa: F401  (this module's interface)
from mpm_fem.app.paper_abstract import (  # noqa: F401  (this module's interface)
    KEY_FIGURES,
    StageOrders,
    abstract,
    abstract_sentences,
    introduction,
    stage_orders,
)
from mpm_fem.app.paper_discussion import (  # noqa: F401  (this module's interface)
    CONCLUSIONS,
    DEPARTS,
    MAX_CONCLUSIONS,
    MEASURED_ELSEWHERE,
    conclusions,
    deep_changes,
    discrepancies,
    discussion,
    drift_section,
)
from mpm_fem.app.paper_findings import (  # noqa: F401  (this module's interface)
    COUNT_MEANING,
    KEY_CHARS,
    Found,
    _clause,
    counted,
    first_clause,
    judge,
    key_text,
    said,
    verdict_text,
)
from mpm_fem.app.paper_method import (  # noqa: F401  (this module's interface)
    SETTINGS,
    burgers_settings,
    deep_text,
    deep_tier_appendix,
    identification_appendix,
    identification_section,
    identification_sentence,
    method,
    rule_book,
    seeds_text,
    settings_appendix,
    settings_table,
    sod_settings,
    terms,
)
from mpm_fem.app.paper_results import (  # noqa: F401  (this module's interface)
    REPRODUCTION,
    claim_figure,
    claim_section,
    evidence,
    evidence_appendix,
    evidence_section,
    failed_runs,
    further_results,
    results,
    verdict_counts,
)


def numbered(lines: list[str]) -> list[str]:
    """``lines`` with the sections after the abstract and before the appendices numbered: ``## Method``
    becomes ``## 2 Method``, its ``### Seeds`` ``### 2.4 Seeds``."""
    out, section, sub, body = [], 0, 0, False
    for line in lines:
        if line.startswith("## "):
            if line.startswith("## Appendix") or line == "## Abstract":
                body = False
            else:
                section, sub, body = section + 1, 0, True
                line = f"## {section} {line[3:]}"
        elif line.startswith("### ") and body:
            sub += 1
            line = f"### {section}.{sub} {line[4:]}"
        out.append(line)
    return out
