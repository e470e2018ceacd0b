"""The documentation site as a reader gets it: built strict, no raw markup left, every
image there, every figure on its page and drawn by today's srarap; and opened in a real
browser (headless Chromium) without console errors or broken images."""
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from browser import find_chromium, open_pages
from helpers import ROOT

sys.path.insert(0, os.path.join(ROOT, "docs"))
from make_figures import FIGURES  # noqa: E402

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    pytest.importorskip("mkdocs", reason="mkdocs is not installed (the docs extra)")
    out = tmp_path_factory.mktemp("site")
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1")
    subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "-q", "-d", str(out)],
                   cwd=ROOT, env=env, check=True, capture_output=True)
    return out


def pages(site):
    return sorted(site.rglob("index.html"))


def test_no_page_shows_raw_markup_or_unset_defaults(site):
    for page in pages(site):
        text = page.read_text(encoding="utf-8")
        body = text[text.index("<article"):text.index("</article>")]
        assert "Sentinel" not in body, page
        assert not re.search(r":(func|meth|class|mod|attr):", body), page
        assert "``" not in body, page


def test_the_cli_reference_states_open_ranges_as_open(site):
    """--alpha must be > 0: the reference said "0 and above" (issue 60)."""
    text = (site / "reference" / "cli" / "index.html").read_text(encoding="utf-8")
    row = re.search(r"<code>--alpha</code>.*?</tr>", text, re.DOTALL)[0]
    assert "0&lt;x" in row and "and above" not in row
    row = re.search(r"<code>--max-iter</code>.*?</tr>", text, re.DOTALL)[0]
    assert "0&lt;=x" in row


def test_every_image_is_there_and_every_figure_is_on_its_pages(site):
    for page in pages(site):
        for src in re.findall(r'<img[^>]+src="([^"]+)"', page.read_text(encoding="utf-8")):
            if not src.startswith(("http:", "https:", "data:")):
                assert (page.parent / src).resolve().is_file(), (page, src)
    for name, where in FIGURES.items():
        for doc in where:
            text = (Path(ROOT, "docs", doc)).read_text(encoding="utf-8")
            assert f"images/{name}" in text, (name, doc)
        assert (site / "images" / name).is_file()


#: figures of measured seconds (the energy against wall time), which no two runs share
TIMED = {"energy.png"}


def test_the_figures_are_what_srarap_draws_today(tmp_path):
    subprocess.run([sys.executable, os.path.join(ROOT, "docs", "make_figures.py"), "--out",
                    str(tmp_path)], check=True, capture_output=True)
    assert all((tmp_path / name).is_file() for name in FIGURES)
    stale = [name for name in sorted(set(FIGURES) - TIMED)
             if not _same_picture(tmp_path / name, Path(ROOT, "docs", "images", name))]
    assert not stale, f"regenerate with python docs/make_figures.py: {stale}"


def _same_picture(a, b):
    """The same bytes, or pixels that differ only by round-off in the shading: a colour map
    of per-vertex values moves a few pixels by a level or two from one machine's BLAS to
    another's; a stale figure (another shape, view, colour or label) moves thousands."""
    if a.read_bytes() == b.read_bytes():
        return True
    import matplotlib.image as mpimg
    import numpy as np

    pa, pb = mpimg.imread(a), mpimg.imread(b)
    if pa.shape != pb.shape:
        return False
    d = np.abs(pa - pb).max(axis=-1)
    return (d > 0).mean() < 1e-3 and d.max() <= 8 / 255


def test_a_browser_opens_every_page_without_errors_or_broken_images(site, tmp_path):
    chromium = find_chromium()
    urls = [str(p.relative_to(site).parent) + "/" for p in pages(site)]
    shot = Path(os.environ.get("SRARAP_SCREENSHOTS", tmp_path)) / "docs-home.png"
    shown, errors = open_pages(chromium, site, urls, tmp_path, screenshot=(urls[0], shot))
    assert not errors, errors
    assert set(shown) == set(urls) and all(n >= 0 for n in shown.values())
    assert shown["./"] >= 1 and shown["guides/handle-files/"] >= 3  # home page, selectors
    assert shown["guides/workflows/"] >= 3
    assert shot.is_file() and shot.stat().st_size > 10_000


def test_what_a_program_prints_wraps_and_code_does_not(site):
    """Issue 70: the stylesheet's rule for program output named ``language-console`` and
    ``language-text``, classes the built pages did not have (a check of the stylesheet's
    text passed all the same). The built page's blocks carry their language, which is what
    the rule selects."""
    page = (site / "guides" / "regression" / "index.html").read_text(encoding="utf-8")
    assert 'class="language-console highlight"' in page
    assert 'class="language-text highlight"' in page
    assert 'class="language-yaml highlight"' in page
    css = (site / "stylesheets" / "extra.css").read_text(encoding="utf-8")
    assert ".md-typeset .language-console pre > code" in css
