"""What a file that no mesh format claims looks like, for its one-line refusal: the commonest
slip is a handle file given as the mesh (the two arguments swapped)."""
import re

from .formats import FORMATS

#: a key at the start of a line of YAML, or of a JSON object
_KEY = re.compile(rb"(?m)^\s*[{\[]?\s*[\"']?([A-Za-z_]+)[\"']?\s*:")
_HANDLE_KEYS = {b"groups", b"region", b"solver"}
_MANIFEST_KEYS = {b"jobs", b"defaults"}


def looks_like(head: bytes) -> str:
    """A few words on what content starting with ``head`` is, ending in advice.

    Examples
    --------
    >>> looks_like(b"groups:\\n  base: {fixed: true}\\n")
    'it looks like a handle file (YAML or JSON): mesh and handles swapped?'
    >>> looks_like(b"")
    'it is empty'
    >>> looks_like(bytes(range(256)))
    'it is binary data of no mesh format srarap reads'
    """
    if not head.strip():
        return "it is empty" if not head else "it holds only white space"
    keys = set(_KEY.findall(head[:4096]))
    if keys & _HANDLE_KEYS and not keys & _MANIFEST_KEYS:
        return "it looks like a handle file (YAML or JSON): mesh and handles swapped?"
    if keys & _MANIFEST_KEYS:
        return "it looks like a batch manifest: give it to 'srarap batch'"
    if re.match(rb"\A\s*(\d+\s*)+\Z", head) or head.lstrip().startswith(b"DMAT"):
        return "it looks like a list of vertex indices (a .sel/.dmat selection), not a mesh"
    if _is_text(head):
        return "it is text of no mesh format srarap reads"
    return "it is binary data of no mesh format srarap reads"


def _is_text(head: bytes) -> bool:
    try:
        head.decode("utf-8")
    except UnicodeDecodeError as exc:
        if exc.start < len(head) - 4:  # not just a character cut at the end of the head
            return False
    return not any(b < 9 or 13 < b < 32 for b in head[:1024])


def not_a_mesh(name: str, head: bytes) -> str:
    """The one-line refusal of ``name``, whose content starts with ``head``, as a mesh."""
    what = looks_like(head)
    if "?" in what or ":" in what:  # the description carries its own advice
        return f"{name}: not a mesh: {what}"
    return (f"{name}: not a mesh: {what} (srarap reads "
            f"{', '.join(f.name.upper() for f in FORMATS.values())})")
