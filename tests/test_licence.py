"""The default install is permissively licensed: no GPL package in srarap's dependency tree."""
import re
from importlib.metadata import PackageNotFoundError, distribution

from packaging.requirements import Requirement


def dependency_tree(name):
    """Installed distributions that ``name`` needs without extras (itself included)."""
    seen, todo = {}, [name]
    while todo:
        key = re.sub(r"[-_.]+", "-", todo.pop()).lower()
        if key in seen:
            continue
        try:
            dist = distribution(key)
        except PackageNotFoundError:
            continue  # an optional or platform-specific requirement that is not installed
        seen[key] = dist
        for text in dist.requires or []:
            req = Requirement(text)
            if req.marker is None or req.marker.evaluate({"extra": ""}):
                todo.append(req.name)
    return seen


def licence_text(dist):
    m = dist.metadata
    classifiers = [c for c in m.get_all("Classifier") or [] if c.startswith("License")]
    return " ".join([m.get("License-Expression") or "", (m.get("License") or "")[:300],
                     *classifiers])


def test_no_gpl_package_in_the_default_install():
    tree = dependency_tree("srarap-cli")
    assert {"numpy", "scipy", "libigl", "click"} <= set(tree)
    assert "pymeshlab" not in tree
    gpl = {k: licence_text(d) for k, d in tree.items()
           if re.search(r"(?<!L)GPL|GNU General Public", licence_text(d))}
    assert gpl == {}
    assert "MIT" in licence_text(tree["srarap-cli"])
