"""The documentation site as a reader gets it: built strict, no raw markup left, every
image there, every figure on its page and drawn by today's srarap; and opened in a real
browser (headless Chromium) without console errors or broken images."""
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from helpers import ROOT

sys.path.insert(0, os.path.join(ROOT, "docs"))
from make_figures import FIGURES  # noqa: E402

pytestmark = pytest.mark.slow
#: set by .ci/run, which installs Chromium: there a missing browser fails instead of skipping
REQUIRE_BROWSER = os.environ.get("SRARAP_REQUIRE_BROWSER") == "1"


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
             if (tmp_path / name).read_bytes() != Path(ROOT, "docs", "images", name).read_bytes()]
    assert not stale, f"regenerate with python docs/make_figures.py: {stale}"


HARNESS = """<!doctype html><html><body><pre id="out">running</pre><script>
const pages = %s;
const out = [];
function next(i) {
  if (i == pages.length) { document.getElementById('out').textContent = 'DONE\\n' + out.join('\\n'); return; }
  const f = document.createElement('iframe');
  f.width = 1280; f.height = 900;
  f.onload = () => setTimeout(() => {
    const imgs = [...f.contentDocument.images];
    for (const img of imgs)
      if (!(img.complete && img.naturalWidth > 0)) out.push('BROKEN ' + pages[i] + ' ' + img.src);
    out.push('PAGE ' + pages[i] + ' ' + imgs.length);
    f.remove(); next(i + 1);
  }, 300);
  f.src = pages[i];
  document.body.appendChild(f);
}
next(0);
</script></body></html>"""


def test_a_browser_opens_every_page_without_errors_or_broken_images(site, tmp_path):
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if chromium is None:
        assert not REQUIRE_BROWSER, "SRARAP_REQUIRE_BROWSER=1 but no chromium on PATH"
        pytest.skip("no Chromium here (Debian's package 'chromium'; .ci/run installs it)")
    urls = [str(p.relative_to(site).parent) + "/" for p in pages(site)]
    (site / "harness.html").write_text(HARNESS % repr(urls).replace("'", '"'))
    server = subprocess.Popen([sys.executable, "-m", "http.server", "0", "-b", "127.0.0.1"],
                              cwd=site, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                              text=True)
    try:
        line = server.stdout.readline()  # "Serving HTTP on 127.0.0.1 port N ..."
        port = re.search(r"port (\d+)", line).group(1)
        base = f"http://127.0.0.1:{port}/"
        r = subprocess.run([chromium, "--headless", "--no-sandbox", "--disable-gpu",
                            "--enable-logging=stderr", "--v=0", "--virtual-time-budget=60000",
                            f"--user-data-dir={tmp_path / 'profile'}", "--dump-dom",
                            base + "harness.html"], capture_output=True, text=True, timeout=300)
        shot = Path(os.environ.get("SRARAP_SCREENSHOTS", tmp_path)) / "docs-home.png"
        subprocess.run([chromium, "--headless", "--no-sandbox", "--disable-gpu",
                        "--hide-scrollbars", "--window-size=1280,1500",
                        f"--user-data-dir={tmp_path / 'profile2'}", f"--screenshot={shot}",
                        base], capture_output=True, timeout=120)
    finally:
        server.terminate()
        server.wait()
    found = re.search(r'<pre id="out">(.*?)</pre>', r.stdout, re.DOTALL)
    report = found.group(1) if found else ""
    assert report.startswith("DONE"), r.stdout[-2000:] + r.stderr[-2000:]
    assert "BROKEN" not in report, report
    assert report.count("PAGE ") == len(urls)
    shown = {page: int(n) for page, n in re.findall(r"PAGE (\S+) (\d+)", report)}
    assert shown["./"] >= 1 and shown["guides/handle-files/"] >= 3  # home page, selectors
    assert shown["guides/workflows/"] >= 3
    errors = [x for x in r.stderr.splitlines() if "CONSOLE" in x and
              re.search(r"error|uncaught|failed", x, re.IGNORECASE)]
    assert not errors, errors
    assert shot.is_file() and shot.stat().st_size > 10_000
