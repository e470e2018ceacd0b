"""Read a YAML or JSON document (handle file, batch manifest) within bounds.

A few hundred bytes of YAML can name a node that aliases expand to 10^9 nodes (a "billion
laughs"), and a deeply nested document overflows the parser's recursion. Both are refused
before anything walks the document: the composed YAML graph is measured with aliases counted
as often as they are used, in time linear in the graph's size.
"""
import json
from typing import Any

import yaml

from ..runtime.errors import InputError
from .input_files import read_input_bytes

#: Largest handle file or manifest read, in bytes (real ones are a few KB).
MAX_BYTES = 16 * 1024 * 1024
#: Most nodes a document may expand to, aliases counted every time they are used.
MAX_NODES = 1_000_000
#: Deepest nesting of mappings and lists.
MAX_DEPTH = 100


def load_document(path: str, kind: str) -> Any:
    """Parsed content of ``path``; ``kind`` is ``"json"`` or ``"yaml"`` (JSON is YAML too).

    Raises
    ------
    InputError : unreadable, too large, too deep, too many nodes, or not valid ``kind``

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as fh:
    ...     _ = fh.write("a: &x [1, 2]\\nb: *x\\n")
    >>> load_document(fh.name, "yaml")
    {'a': [1, 2], 'b': [1, 2]}
    >>> os.unlink(fh.name)
    """
    data = read_input_bytes(path)
    if len(data) > MAX_BYTES:
        raise InputError(f"{path}: {len(data)} bytes; a {kind.upper()} document here is at most "
                         f"{MAX_BYTES} bytes")
    try:
        text = data.decode("utf-8")
        if kind == "json":
            doc = json.loads(text)
            _check_tree(doc, path)
            return doc
        _check_graph(yaml.compose(text, Loader=yaml.SafeLoader), path)
        return yaml.safe_load(text)
    except InputError:
        raise
    except RecursionError:
        raise InputError(f"{path}: nested too deeply (at most {MAX_DEPTH} levels)") from None
    except UnicodeDecodeError as exc:
        raise InputError(f"{path}: not UTF-8 text (byte {exc.start})") from None
    except (ValueError, yaml.YAMLError) as exc:
        first = _reason(exc)
        mark = getattr(exc, "problem_mark", None)
        where = f" (line {mark.line + 1}, column {mark.column + 1})" if mark is not None else ""
        raise InputError(f"{path}: not valid {kind.upper()}{where}: {first[:200]}") from None


def _reason(exc):
    """What is wrong, in one line: YAML's problem ("found character '\\t' that cannot start
    any token") before its context ("while scanning for the next token"), which its first
    line holds alone."""
    problem, context = getattr(exc, "problem", None), getattr(exc, "context", None)
    if problem:
        return problem + (f" ({context})" if context else "")
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__


def _children(node):
    if isinstance(node, yaml.MappingNode):
        return [part for pair in node.value for part in pair]
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    return []


def _check_graph(root, path):
    """Refuse a composed YAML graph that expands past MAX_NODES or MAX_DEPTH."""
    if root is None:
        return
    size: dict[int, int] = {}
    depth: dict[int, int] = {}
    open_ = set()  # nodes whose children are being measured: meeting one again is a cycle
    stack = [(root, False)]
    while stack:
        node, done = stack.pop()
        key = id(node)
        if key in size:
            continue
        kids = _children(node)
        if not done:
            if key in open_:
                continue  # the same node queued twice before it was measured
            open_.add(key)
            stack.append((node, True))
            for kid in kids:
                if id(kid) in open_:
                    raise InputError(f"{path}: refers to itself (an alias used inside the "
                                     "node it names"
                                     + (f", line {kid.start_mark.line + 1}" if getattr(
                                         kid, "start_mark", None) else "") + ")")
                if id(kid) not in size:
                    stack.append((kid, False))
            continue
        open_.discard(key)
        size[key] = 1 + sum(size[id(k)] for k in kids)
        depth[key] = 1 + max((depth[id(k)] for k in kids), default=0)
        if size[key] > MAX_NODES:
            raise InputError(f"{path}: expands to more than {MAX_NODES} nodes (aliases "
                             "counted where they are used)")
        if depth[key] > MAX_DEPTH:
            raise InputError(f"{path}: nested too deeply (at most {MAX_DEPTH} levels)")


def _check_tree(doc, path):
    stack = [(doc, 1)]
    while stack:
        item, level = stack.pop()
        if level > MAX_DEPTH:
            raise InputError(f"{path}: nested too deeply (at most {MAX_DEPTH} levels)")
        if isinstance(item, dict):
            stack.extend((v, level + 1) for v in item.values())
        elif isinstance(item, list):
            stack.extend((v, level + 1) for v in item)
