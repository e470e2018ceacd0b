"""MkDocs hooks: what the generated references need before a reader sees them.

The command-line reference's Default column:

mkdocs-click prints Click's ``Sentinel.UNSET`` for an option without a default. Every srarap
option of that kind either says its default in its help (``[default: 0.14]``: the solver
settings, whose value comes from the handle file or the defaults) or is a flag or has none;
the column gets that default, ``off`` for a flag, and ``-`` otherwise. Its Type column: a
range as Click writes it (``x>0``), where mkdocs-click said "`0` and above" for open bounds.
"""
import re

import click
from mkdocs_click import _docs

_MKDOCS_CLICK_TYPE = _docs._format_table_option_type

ROW = re.compile(r"<tr>\s*<td>(?P<name>.*?)</td>\s*<td>(?P<type>.*?)</td>\s*"
                 r"<td>(?P<help>.*?)</td>\s*<td><code>Sentinel\.UNSET</code></td>\s*</tr>",
                 re.DOTALL)
SAID = re.compile(r"\[default: (?P<value>[^\]]*)\]")


def _row(match):
    said = SAID.search(match["help"])
    if said:
        default = f"<code>{said['value']}</code>"
    elif match["type"].strip() == "boolean":
        default = "off"
    else:
        default = "-"
    return (f"<tr>\n<td>{match['name']}</td>\n<td>{match['type']}</td>\n"
            f"<td>{match['help']}</td>\n<td>{default}</td>\n</tr>")


def _cli(html):
    return ROW.sub(_row, html) if "Sentinel." in html else html


# The API reference: the docstrings are numpydoc written for readers of the source, where
# ``name : what it is`` often says more than a type and Sphinx roles name other objects.
ROLE = re.compile(r":(?:func|meth|class|mod|attr|data|exc|obj):(?:<code>|`)~?([\w.]+)(?:</code>|`)")
DOUBLED = re.compile(r"``([^`]*)``")
TYPE_CELL = re.compile(r'(<tr class="doc-section-item">\s*<td>\s*<code>[^<]*</code>\s*</td>\s*)'
                       r"<td>\s*<code>(?P<type>[^<]*)</code>\s*</td>\s*"
                       r'<td>\s*<div class="doc-md-description">\s*(?P<desc>.*?)\s*</div>',
                       re.DOTALL)
#: a "type" this long, or with words a type does not have, is the start of a description
TYPE_WORDS = re.compile(r"\b(the|a|an|of|or|and|from|for|in|with|to|each|one|per)\b")


def _short(match):
    """A role's target by its last name (``~`` or not): the page says where it lives."""
    return f"<code>{match[1].rsplit('.', 1)[-1]}</code>"


def _type_cell(match):
    kind = match["type"]
    if len(kind) <= 40 and not TYPE_WORDS.search(kind):
        return match[0]
    desc = match["desc"]
    if desc.startswith("<p>"):
        desc = f"<p>{kind} {desc[3:]}"
    else:
        desc = f"<p>{kind}</p>{desc}"
    return (f"{match[1]}<td></td>\n<td>\n<div class=\"doc-md-description\">{desc}</div>")


def _api(html):
    html = TYPE_CELL.sub(_type_cell, html)
    html = ROLE.sub(_short, html)
    return DOUBLED.sub(r"\1", html)


def _range_type(option):
    """An option's type as the table says it, with its range as Click states it (``x>0``):
    mkdocs-click says "`0` and above" for an open bound too (``--alpha`` must be > 0)."""
    kind = option.type
    if isinstance(kind, (click.IntRange, click.FloatRange)):
        return f"{kind.name} (`{kind._describe_range()}`)"
    return _MKDOCS_CLICK_TYPE(option)


def on_config(config):
    """MkDocs' hook, before any page: the range column fixed where mkdocs-click builds it."""
    global _MKDOCS_CLICK_TYPE
    if _docs._format_table_option_type is not _range_type:
        _MKDOCS_CLICK_TYPE = _docs._format_table_option_type
        _docs._format_table_option_type = _range_type
    return config


def on_page_content(html, page, config, files):
    """MkDocs' hook: the command-line and API references' fixes."""
    html = _cli(html)
    return _api(html) if page.file.src_uri == "reference/api.md" else html
