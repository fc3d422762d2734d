"""The report's Markdown: table cells, tables, figures, anchors, and prose cut into short paragraphs.

A paragraph of the report holds at most :data:`MAX_WORDS` words: :func:`paragraphs` packs whole
sentences into paragraphs under that limit, cutting a sentence that is longer by itself at its
semicolons, then at its commas, never inside a number or a name. :func:`words_of_paragraphs` counts
the words of every paragraph (a list item counts as a paragraph of its own; headings, tables,
figures and anchors are not prose), so a test can hold the report to the limit.
"""

from __future__ import annotations

import math
import re

#: The longest paragraph of the report, in words.
MAX_WORDS = 120
#: A sentence ends at a full stop, question or exclamation mark followed by a space and a capital.
_SENTENCE_END = re.compile(r"(?<=[.!?])\s+(?=[A-Z(`*])")


def cell(value) -> str:
    """One table cell: numbers to four significant digits, text with its pipes escaped, a number that is not
    one (``nan``, empty for a whole cell) written ``-`` inside a text."""
    text = str(value).strip()
    try:
        number = float(text)
    except ValueError:
        return _NAN.sub("-", text).replace("|", "\\|").replace("\n", " ")
    if not math.isfinite(number):
        return ""
    if text.lstrip("-").isdigit():
        return text
    return format(number, ".4g")


def markdown_table(rows: list[dict] | tuple[dict, ...], columns: tuple[str, ...] | list[str] = ()) -> list[str]:
    """A Markdown table of ``rows`` in ``columns`` (every column of the first row when empty)."""
    columns = list(columns) or list(rows[0])
    lines = ["| " + " | ".join(str(c).replace("|", "\\|") for c in columns) + " |", "|" + "---|" * len(columns)]
    return lines + ["| " + " | ".join(cell(r.get(c, "")) for c in columns) + " |" for r in rows]


def figure(page: str, file: str, captions: dict) -> list[str]:
    """The figure ``file`` of the study folder ``page``, with its caption below it."""
    caption = captions.get(file, file)
    return [f"![{caption}]({page}/{file})", "", f"*{caption}*", ""]


def anchor_of(label: str) -> str:
    """The anchor of a claim's label: ``"C3 (sod)"`` -> ``"c3-sod"``."""
    return label.lower().replace(" (", "-").replace(")", "")


def word_count(text: str) -> int:
    return len(text.split())


def sentences(text: str) -> list[str]:
    """``text`` cut into its sentences (a full stop followed by a capital ends one)."""
    return [s.strip() for s in _SENTENCE_END.split(text.strip()) if s.strip()]


def split_outside(text: str, mark: str = ";") -> list[str]:
    """``text`` cut at every ``mark`` outside parentheses and brackets, each piece stripped."""
    pieces, depth, current = [], 0, ""
    for char in text:
        depth += (char in "([") - (char in ")]")
        if char == mark and depth <= 0:
            pieces.append(current)
            current = ""
        else:
            current += char
    return [p.strip() for p in pieces + [current] if p.strip()]


def _pieces(sentence: str, limit: int) -> list[str]:
    """A sentence longer than ``limit`` words cut at its semicolons, then at its commas."""
    if word_count(sentence) <= limit:
        return [sentence]
    for mark in ("; ", ", "):
        parts = split_outside(sentence, mark[0])
        if len(parts) > 1:
            out, current = [], ""
            for part in parts:
                longer = f"{current}{mark}{part}" if current else part
                if current and word_count(longer) > limit:
                    out.append(current + mark.strip())
                    current = part
                else:
                    current = longer
            out.append(current)
            return [p for piece in out for p in _pieces(piece, limit)] if len(out) > 1 else out
    return [sentence]


def paragraphs(text: str, limit: int = MAX_WORDS) -> list[str]:
    """``text`` as paragraphs of at most ``limit`` words each, whole sentences packed in order."""
    out, current = [], ""
    for piece in (p for s in sentences(text) for p in _pieces(s, limit)):
        longer = f"{current} {piece}" if current else piece
        if current and word_count(longer) > limit:
            out.append(current)
            current = piece
        else:
            current = longer
    return out + ([current] if current else [])


def prose(text: str, limit: int = MAX_WORDS) -> list[str]:
    """The Markdown lines of ``text`` as :func:`paragraphs`, each followed by a blank line."""
    return [line for p in paragraphs(text, limit) for line in (p, "")]


def bullets(items: list[str], limit: int = MAX_WORDS) -> list[str]:
    """A bullet list, an item longer than ``limit`` words continued as further items; the items apart
    (a blank line between them), so that each is a paragraph of its own within ``limit`` words, its
    marker counted."""
    return [line for item in items for p in paragraphs(item, limit - 1) for line in (f"- {p}", "")]


def _is_prose(block: str) -> bool:
    return not block.startswith(("#", "|", "![", "<a id=", "<!--"))


def words_of_paragraphs(markdown: str) -> list[tuple[int, str]]:
    """``(words, first words)`` of every paragraph of ``markdown``: a block of lines between blank
    lines, a list's markers counted and a tight list (items without a blank line between them) one
    block; headings, tables, figures, anchors and comments are left out."""
    blocks = (block.strip() for block in re.split(r"\n\s*\n", markdown))
    return [(word_count(block), " ".join(block.split()[:8])) for block in blocks if block and _is_prose(block)]


def headings_without_content(markdown: str) -> list[str]:
    """The headings of ``markdown`` followed by another heading or by nothing (anchors aside)."""
    lines = [line for line in markdown.splitlines() if line.strip() and not line.startswith("<a id=")]
    return [line for k, line in enumerate(lines) if line.startswith("#")
            and (k + 1 == len(lines) or lines[k + 1].startswith("#"))]


_NAN = re.compile(r"(?<![\w.])nan(?![\w.])", re.IGNORECASE)
_RANGE = re.compile(r"(?<![\w.])(-?\d+(?:\.\d+)?)\.\.(-?\d+(?:\.\d+)?)(?![\w.])")
_EXPONENT = re.compile(r"(?<![\w.])(\d(?:\.\d+)?)e\+0*(\d+)(?![\w.])")


def readable(text: str) -> str:
    """A sentence's numbers as prose writes them: a range ``1.00..1.45`` as ``1.00 to 1.45`` and a number in
    exponent form of at most two significant digits, ``7.6e+02``, as ``760``; everything else unchanged."""
    text = _RANGE.sub(r"\1 to \2", text)
    return _EXPONENT.sub(lambda m: f"{float(m.group(0)):.0f}", text)

