"""Headless Chromium for the tests that look at pages as a reader does: console errors and
images that do not load. Skips where there is no Chromium, unless SRARAP_REQUIRE_BROWSER=1
(.ci/run, which installs Debian's package, sets it)."""
import os
import re
import shutil
import subprocess
import sys

import pytest

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




#: headless, and no connections of its own: on a closed network Chromium's background
#: services (updates, sync, Google's hosts) only fail, many at a time
QUIET = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync"]


def find_chromium():
    """The Chromium executable; skips the test (fails under SRARAP_REQUIRE_BROWSER=1)."""
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if chromium is None:
        assert os.environ.get("SRARAP_REQUIRE_BROWSER") != "1", \
            "SRARAP_REQUIRE_BROWSER=1 but no chromium on PATH"
        pytest.skip("no Chromium here (Debian's package 'chromium'; .ci/run installs it)")
    return chromium


def open_pages(chromium, folder, urls, tmp_path, screenshot=None):
    """Open each of ``urls`` (relative to ``folder``, served over HTTP) in a frame of one
    headless Chromium page. Returns ({url: images on it}, [console errors and images that
    did not load]); ``screenshot`` (url, path) also saves a picture of one page."""
    (folder / "harness.html").write_text(HARNESS % repr(list(urls)).replace("'", '"'))
    server = subprocess.Popen([sys.executable, "-m", "http.server", "0", "-b", "127.0.0.1"],
                              cwd=folder, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                              text=True)
    try:
        port = re.search(r"port (\d+)", server.stdout.readline()).group(1)
        base = f"http://127.0.0.1:{port}/"
        r = subprocess.run([chromium, *QUIET, "--enable-logging=stderr", "--v=0",
                            "--virtual-time-budget=60000",
                            f"--user-data-dir={tmp_path / 'profile'}", "--dump-dom",
                            base + "harness.html"], capture_output=True, text=True, timeout=300)
        if screenshot is not None:
            url, path = screenshot
            subprocess.run([chromium, *QUIET, "--hide-scrollbars", "--window-size=1280,1500",
                            f"--user-data-dir={tmp_path / 'profile2'}", f"--screenshot={path}",
                            base + url], capture_output=True, timeout=120)
    finally:
        server.terminate()
        server.wait()
    found = re.search(r'<pre id="out">(.*?)</pre>', r.stdout, re.DOTALL)
    report = found.group(1) if found else ""
    assert report.startswith("DONE"), r.stdout[-2000:] + r.stderr[-2000:]
    shown = {page: int(n) for page, n in re.findall(r"PAGE (\S+) (\d+)", report)}
    errors = [x for x in report.splitlines() if x.startswith("BROKEN")]
    errors += [x for x in r.stderr.splitlines() if "CONSOLE" in x and
               re.search(r"error|uncaught|failed", x, re.IGNORECASE)]
    return shown, errors
