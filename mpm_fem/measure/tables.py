"""Reading the tables the studies write: ``<study>/<table>.csv`` with ``<table>.json`` beside it.

A table is a list of rows, each a dict of strings as read from the CSV. :func:`load_tables` reads a
whole figures folder into ``{"<study>/<table>": rows}`` and adds two tables built from the JSON
files: ``versions`` (one row per table: ``table``, ``code``, ``quick``, ``tier``: :func:`table_tier`) and
``settings`` (one row per setting: ``table``, ``key`` with dots for nesting, ``value``). Claims read only this mapping.
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


#: The tier of a table that records none (:func:`table_tier`): another tier than any a study writes.
UNSTAMPED = "unstamped"


def table_tier(meta: dict) -> str:
    """The tier of a table from its JSON ``meta``: its ``tier`` stamp (``quick``, ``full`` or ``deep``);
    for a table written before the stamp, the ``tier`` or else the ``quick`` flag of its settings
    (``quick: false`` reads as ``full``); :data:`UNSTAMPED` when it records none of them."""
    settings = meta.get("settings", {}) if isinstance(meta.get("settings"), dict) else {}
    if meta.get("tier"):
        return str(meta["tier"])
    if settings.get("tier"):
        return str(settings["tier"])
    if isinstance(settings.get("quick"), bool):
        return "quick" if settings["quick"] else "full"
    return UNSTAMPED


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
                                   "quick": str(settings.get("quick", "")), "tier": table_tier(meta)})
        tables["settings"] += [{"table": name, "key": k, "value": v} for k, v in _flatten(settings)]
    return tables


def tiers(folder: Path) -> dict[str, str]:
    """``{"<study>/<table>": tier}`` of every table under ``folder`` (:func:`table_tier`), reading only
    the JSON beside each CSV."""
    found = {}
    for path in sorted(Path(folder).glob("*/*.csv")):
        meta_path = path.with_suffix(".json")
        meta = json.loads(meta_path.read_text()) if meta_path.exists() else {}
        found[f"{path.parent.name}/{path.stem}"] = table_tier(meta)
    return found


def setting(tables: Tables, table: str, key: str, default: str = "") -> str:
    """The value of setting ``key`` (dotted) recorded with ``table``, or ``default``."""
    return next((r["value"] for r in tables.get("settings", []) if r["table"] == table and r["key"] == key), default)
