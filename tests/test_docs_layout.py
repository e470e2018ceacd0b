"""The docs site's code blocks fit their column: at 1280 px wide (the theme's content column
beside both sidebars) a code block shows 88 characters, and a longer line is cut at the
block's edge, its end (often the part that matters) behind a scroll bar. What a program
prints (``text``, ``console`` blocks) wraps instead (docs/stylesheets/extra.css)."""
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
COLUMN = 84  # 86 shown whole at 1280 px in headless Chromium (a screenshot); 2 to spare
WRAPPED = {"text", "console"}
FENCE = re.compile(r"^\s*```(?P<lang>[\w-]*)")


def code_lines(page: Path):
    """(line number, language, text) of each line inside a fenced block of ``page``."""
    lang = None
    for number, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1):
        fence = FENCE.match(line)
        if fence:
            lang = fence["lang"] if lang is None else None
        elif lang is not None:
            yield number, lang, line


PAGES = sorted((ROOT / "docs").rglob("*.md"))


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_code_blocks_fit_the_column(page):
    long = [f"{page.name}:{n} ({len(text)} chars)" for n, lang, text in code_lines(page)
            if lang not in WRAPPED and len(text.rstrip()) > COLUMN]
    assert not long


def test_what_programs_print_wraps_in_the_stylesheet():
    css = (ROOT / "docs" / "stylesheets" / "extra.css").read_text(encoding="utf-8")
    for lang in WRAPPED:
        assert f".language-{lang} pre > code" in css
    assert "white-space: pre-wrap" in css


def test_the_reader_sees_fences_the_way_this_test_does():
    page = ROOT / "docs" / "guides" / "regression.md"
    langs = {lang for _, lang, _ in code_lines(page)}
    assert {"yaml", "console", "text", "python"} <= langs
