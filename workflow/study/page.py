"""The HTML page every campaign report is written on: one self-contained file (figures
embedded), a table of contents, and the provenance of the code and packages that made it."""
from __future__ import annotations

import base64
import datetime as _dt
import html
import os
import platform
import subprocess
from pathlib import Path

CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;max-width:1200px;margin:2em auto;
padding:0 1em;color:#222}
h1{font-size:1.6em}h2{border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:2em}
table{border-collapse:collapse;font-size:.85em}td,th{border:1px solid #ddd;padding:3px 6px;text-align:right}
th{background:#f3f3f3}td.l,th.l{text-align:left}tr.diverged td{background:#fde2e1}tr.not_steady td{background:#fff4d6}
td.reason,td .reason{white-space:normal;overflow-wrap:anywhere;max-width:32em;display:inline-block}
section{overflow-x:auto}
figure{margin:1.5em 0}figcaption{font-size:.9em;color:#444;max-width:900px}img{max-width:100%}
pre{background:#f7f7f7;padding:.8em;overflow-x:auto;font-size:.85em}
nav ul{display:flex;flex-wrap:wrap;gap:.3em 1.2em;list-style:none;padding:0;margin:0}
p.lead{font-size:1.05em}td.ok{background:#d9f2e6}td.warn{background:#fff4d6}td.bad{background:#fde2e1}
table.verdict td{vertical-align:top}table.verdict td.l{max-width:640px}
"""
SOURCE = Path(__file__).resolve().parent  # the commit is read here, wherever the campaign runs


def commit() -> str:
    """The short commit of the code that wrote the report ('unknown' outside a git checkout)."""
    try:
        out = subprocess.run(["git", "-C", str(SOURCE), "rev-parse", "--short", "HEAD"], capture_output=True,
                             text=True, timeout=5).stdout.strip()
    except Exception:
        return "unknown"
    return out or "unknown"


def provenance(numba_version: str = "") -> dict:
    """Date, commit, host, working directory, and the versions of Python, sph-surge, numpy,
    xarray, matplotlib, snakemake and numba."""
    import matplotlib
    import numpy
    import snakemake
    import xarray

    import solver
    return {"date (UTC)": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M"),
            "commit": commit(), "host": platform.node(), "python": platform.python_version(),
            "sph-surge": solver.__version__, "numpy": numpy.__version__, "xarray": xarray.__version__,
            "matplotlib": matplotlib.__version__, "snakemake": snakemake.__version__,
            "numba": numba_version, "cwd": os.getcwd()}


def provenance_html(numba_version: str = "") -> str:
    return "<table>" + "".join(f'<tr><th class="l">{html.escape(k)}</th><td class="l">{html.escape(str(v))}</td></tr>'
                               for k, v in provenance(numba_version).items()) + "</table>"


def reason_html(text) -> str:
    """A run's status or reason for a table cell, wrapped within the cell however long."""
    return f"<span class='reason'>{html.escape(str(text))}</span>" if text else ""


def figure_html(path, title: str, caption: str) -> str:
    """A figure embedded in the page (base64), with its title and caption."""
    data = base64.b64encode(Path(path).read_bytes()).decode()
    mime = "image/svg+xml" if str(path).endswith(".svg") else "image/png"
    return (f'<figure id="{html.escape(Path(path).stem)}"><h3>{html.escape(title)}</h3>'
            f'<img alt="{html.escape(title)}" src="data:{mime};base64,{data}">'
            f"<figcaption>{html.escape(caption)}</figcaption></figure>")


def page(title: str, heading: str, lead: str, body: list[tuple[str, str]]) -> str:
    """The self-contained HTML page: heading, lead, a table of contents, then each (title, html)
    section."""
    toc = "".join(f'<li><a href="#{t.lower().replace(" ", "-")}">{html.escape(t)}</a></li>' for t, _ in body)
    sections = "".join(f'<section id="{t.lower().replace(" ", "-")}"><h2>{html.escape(t)}</h2>{c}</section>'
                       for t, c in body)
    return (f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
            f"<title>{html.escape(title)}</title><style>{CSS}</style></head><body>"
            f"<h1>{html.escape(heading)}</h1>{lead}<nav><ul>{toc}</ul></nav>{sections}</body></html>")


def write(text: str, path) -> None:
    """Write the page atomically."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(text, encoding="utf-8")
    tmp.replace(path)
