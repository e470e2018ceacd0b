"""Every warning srarap gives, by a short stable code and one of two kinds.

A warning is about the user's **request** (a motion that mirrors, whole turns, a units
mistake, a part carried off rigidly or left at rest, keyframes no frame reaches, data the
output format drops) or it is a **note** on something srarap handles (needle, duplicate or
zero-area faces, coincident or non-manifold vertices, its own simplification). ``strict``
fails a run on the first kind (``all``: on both), less the codes ``allow`` accepts; a CI gate
can then stay on over real meshes, whose notes are many and harmless.

A warning is a :class:`Note`: a ``str`` (everything that lists, counts, writes or prints
warnings keeps working) whose text ends with its code in brackets, as compilers write theirs
(``... [needles]``), so a summary, a record read back or a JUnit file carries the code too.

Examples
--------
>>> w = note("needles", "3 needle faces")
>>> w, w.code, w.kind
('3 needle faces [needles]', 'needles', 'note')
>>> as_note("3 needle faces [needles]").kind
'note'
>>> [str(w) for w in failing([w, note("units", "far")], "request", ())]
['far [units]']
"""
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

REQUEST, NOTE = "request", "note"
#: what ``strict`` takes: off, the request's warnings, or all of them
LEVELS = ("off", REQUEST, "all")


@dataclass(frozen=True)
class Code:
    """One kind of warning: its ``name`` (what ``allow`` takes), ``kind`` and what it means
    (the docs' table)."""

    name: str
    kind: str
    meaning: str


CODES = {c.name: c for c in (
    # what the user asked
    Code("units", REQUEST, "a group's targets lie farther than the mesh's bounding-box "
                           "diagonal from its rest positions (other units, another mesh)"),
    Code("angle-unit", REQUEST, "an angle whose unit looks mistaken: angle_rad beyond a full "
                                "turn, or angle (degrees) without saying which"),
    Code("whole-turns", REQUEST, "a static rotation of whole turns: the targets are the rest "
                                 "pose"),
    Code("short-way", REQUEST, "a static rotation beyond 180 degrees, which a solve turns the "
                               "short way"),
    Code("non-unit-quaternion", REQUEST, "a quaternion whose length is not 1, normalized"),
    Code("not-rigid", REQUEST, "a matrix no rigid motion reaches (it mirrors, scales or "
                               "shears)"),
    Code("rigid-part", REQUEST, "a connected part held only by handles that move it rigidly: "
                                "it moves as one piece (the whole mesh, when it is one part: "
                                "a fixed group forgotten?)"),
    Code("no-motion", REQUEST, "every handle keeps its rest position (only fixed groups): the "
                               "result is the rest shape"),
    Code("all-held", REQUEST, "every vertex is constrained: the result is the targets, "
                              "nothing is solved"),
    Code("part-at-rest", REQUEST, "a connected part without a constrained vertex: kept at "
                                  "rest"),
    Code("unreached-keys", REQUEST, "keyframes after an animation's last frame"),
    Code("format-drops", REQUEST, "data of the input the output format cannot hold (texture "
                                  "coordinates, normals, polygons split, per-vertex data)"),
    Code("negative-weights", REQUEST, "--weights cotan on a mesh with obtuse angles: negative "
                                      "edge weights, the energy is not bounded below"),
    Code("multires-size", REQUEST, "a multires size not below the mesh's vertex count: "
                                   "solved directly"),
    Code("cache-unwritable", REQUEST, "the --cache folder cannot be written: the next run "
                                      "simplifies again"),
    # what srarap handles
    Code("collapsed-faces", NOTE, "faces that repeat a vertex, left out of the solve"),
    Code("duplicate-faces", NOTE, "faces with the same vertices as another face"),
    Code("zero-area", NOTE, "zero-area faces, which give their edges no weight"),
    Code("degenerate-angles", NOTE, "angles of zero-area faces with no finite cotangent, "
                                    "weighted 0"),
    Code("needles", NOTE, "needle faces (an angle under 1 degree): cotangents capped at 1000"),
    Code("non-manifold", NOTE, "non-manifold edges or vertices: solved, the operators are "
                               "defined there"),
    Code("coincident-vertices", NOTE, "border vertices on another vertex: the surface is cut "
                                      "open there"),
    Code("unreferenced-vertices", NOTE, "vertices in no triangle: kept at rest or placed at "
                                        "their targets"),
    Code("coarse-topology", NOTE, "the multiresolution coarse mesh's topology differs from "
                                  "the mesh's"),
    Code("coarse-size", NOTE, "the simplification stopped above the size asked: no further "
                              "collapse keeps the surface valid"),
    Code("cache-entry", NOTE, "an unreadable or inconsistent cache entry: simplified again"),
    Code("multires-no-gain", NOTE, "the mesh simplifies too little for a coarse level: "
                                   "solved at full resolution"),
    Code("stale-frames", NOTE, "frames of an earlier, longer animation removed"),
)}
_TAIL = re.compile(r" \[([a-z-]+)\]\Z")


class Note(str):
    """A warning: its text with `` [code]`` at the end; ``code`` and ``kind`` attributes."""

    code: str
    kind: str

    def __new__(cls, code: str, text: str) -> "Note":
        if code not in CODES:
            raise ValueError(f"unknown warning code {code!r}")
        self = super().__new__(cls, f"{text} [{code}]")
        self.code, self.kind = code, CODES[code].kind
        return self

    @property
    def text(self) -> str:
        """The warning without its code."""
        return self[:-len(self.code) - 3]

    def __reduce__(self):  # pickled to a worker process and back
        return Note, (self.code, self.text)


def note(code: str, text: str) -> Note:
    """The warning ``text`` with its ``code`` (one of :data:`CODES`)."""
    return Note(code, text)


def reworded(w: str, prefix: str) -> str:
    """``w`` with ``prefix`` before its text, its code kept."""
    found = as_note(w)
    return note(found.code, prefix + found.text) if isinstance(found, Note) else prefix + w


def as_note(w: str) -> "Note | str":
    """``w`` as a :class:`Note` when its text ends with a known code (a warning read back
    from a record, a cache or a summary), else ``w`` itself."""
    if isinstance(w, Note):
        return w
    found = _TAIL.search(w)
    if found and found.group(1) in CODES:
        return Note(found.group(1), w[:found.start()])
    return w


def coded(w: str, code: str) -> Note:
    """``w`` as a :class:`Note`: its own code where it has one, else ``code``."""
    found = as_note(w)
    return found if isinstance(found, Note) else note(code, w)


def kind_of(w: str) -> str:
    """A warning's kind; one without a code (a plug-in's) counts as the request's."""
    found = as_note(w)
    return found.kind if isinstance(found, Note) else REQUEST


def failing(warnings: Iterable[str], strict: str, allow: Sequence[str]) -> list[str]:
    """The distinct ``warnings`` that fail a run under ``strict`` (one of :data:`LEVELS`)
    with the codes ``allow`` accepts, in order."""
    if strict == "off":
        return []
    out = []
    for w in dict.fromkeys(warnings):
        found = as_note(w)
        code = found.code if isinstance(found, Note) else None
        if code in allow or (strict == REQUEST and kind_of(found) != REQUEST):
            continue
        out.append(w)
    return out


def parse_level(value: object) -> str:
    """``strict``'s value: true is ``request``, false ``off``; raises ValueError else."""
    if value is True:
        return REQUEST
    if value is False:
        return "off"
    if value not in LEVELS:
        raise ValueError(f"must be true, false or one of {', '.join(LEVELS)}")
    return str(value)


def parse_codes(value: object) -> tuple[str, ...]:
    """``allow``'s value, a code or a list of codes, as a tuple in the table's order;
    raises ValueError naming an unknown one."""
    items = [value] if isinstance(value, str) else value
    if not isinstance(items, (list, tuple)) or not all(isinstance(i, str) for i in items):
        raise ValueError("must be a warning code or a list of them")
    for name in items:
        if name not in CODES:
            raise ValueError(f"has no warning code {name!r} (codes: {', '.join(CODES)})")
    return tuple(c for c in CODES if c in items)


def markdown_table() -> str:
    """The codes as the docs' Markdown table (``docs/make_tables.py`` writes it)."""
    rows = ["| code | kind | fails under | what it says |", "|---|---|---|---|"]
    for c in CODES.values():
        under = "`--strict`" if c.kind == REQUEST else "`--strict=all`"
        rows.append(f"| `{c.name}` | {c.kind} | {under} | {c.meaning} |")
    return "\n".join(rows) + "\n"
