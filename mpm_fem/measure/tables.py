"""Reading the tables the studies write: ``<study>/<table>.csv`` with ``<table>.json`` beside it.

A table is a list of rows, each a dict of strings as read from the CSV. :func:`load_tables` reads a
whole figures folder into ``{"<study>/<table>": rows}`` and adds two tables built from the JSON
files: ``versions`` (one row per table: ``table``, ``code``, ``quick``) and ``settings`` (one row per
setting: ``table``, ``key`` with dots for nesting, ``value``). Claims read only this mapping.
No project imports: writing lives in :mod:`mpm_fem.app.study`.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

Tables = dict[str, list[dict]]


def read_table(path: Path) -> list[dict]:
    """Rows of a CSV table (values as strings)."""
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def _flatten(value, prefix: str = "") -> list[tuple[str, str]]:
    if isinstance(value, dict):
        return [kv for k, v in value.items() for kv in _flatten(v, f"{prefix}.{k}" if prefix else str(k))]
    return [(prefix, json.dumps(value) if isinstance(value, list) else str(value))]


def load_tables(folder: Path) -> Tables:
    """Every ``<study>/<table>.csv`` under ``folder``, plus the ``versions`` and ``settings`` tables."""
    folder = Path(folder)
    tables: Tables = {"versions": [], "settings": []}
    for path in sorted(folder.glob("*/*.csv")):
        name = f"{path.parent.name}/{path.stem}"
        tables[name] = read_table(path)
        meta_path = path.with_suffix(".json")
        meta = json.loads(meta_path.read_text()) if meta_path.exists() else {}
        settings = meta.get("settings", {})
        tables["versions"].append({"table": name, "code": str(meta.get("code", "")),
                                   "quick": str(settings.get("quick", ""))})
        tables["settings"] += [{"table": name, "key": k, "value": v} for k, v in _flatten(settings)]
    return tables


def setting(tables: Tables, table: str, key: str, default: str = "") -> str:
    """The value of setting ``key`` (dotted) recorded with ``table``, or ``default``."""
    return next((r["value"] for r in tables.get("settings", []) if r["table"] == table and r["key"] == key), default)
