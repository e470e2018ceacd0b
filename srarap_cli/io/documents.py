"""Read a YAML or JSON document (handle file, batch manifest) within bounds, and refuse a
key given twice in one mapping (both loaders keep the last one without a word).

A few hundred bytes of YAML can name a node that aliases expand to 10^9 nodes (a "billion
laughs"), and a deeply nested document overflows the parser's recursion. Both are refused
before anything walks the document: the composed YAML graph is measured with aliases counted
as often as they are used, in time linear in the graph's size.
"""
import json
import os
import select
import stat
import sys
import time
from typing import Any

import yaml

from ..runtime.errors import InputError, plain
from .input_files import BOM, read_input_bytes

#: Largest handle file or manifest read, in bytes (real ones are a few KB).
MAX_BYTES = 16 * 1024 * 1024
#: Most nodes a document may expand to, aliases counted every time they are used.
MAX_NODES = 1_000_000
#: Deepest nesting of mappings and lists.
MAX_DEPTH = 100


def load_document(path: str, kind: str) -> Any:
    """Parsed content of ``path``; ``kind`` is ``"json"``, ``"yaml"`` (JSON is YAML too) or
    ``"content"`` (JSON where the text starts with ``{`` or ``[``, else YAML). ``path`` may
    be a stream (see :func:`document_bytes`).

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
    data = document_bytes(path)
    size = f"more than {MAX_BYTES}" if is_stream(path) else str(len(data))  # a stream: cut
    path = "<stdin>" if path == "-" else path  # as the messages name it
    if kind == "content":
        kind = "json" if data.lstrip()[:1] in (b"{", b"[") else "yaml"
    if len(data) > MAX_BYTES:
        raise InputError(f"{path}: {size} bytes; a {kind.upper()} document here is at most "
                         f"{MAX_BYTES} bytes")
    try:
        text = data.decode("utf-8")
        if kind == "json":
            doc = json.loads(text, object_pairs_hook=lambda pairs: _unique(pairs, text, path))
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


def is_stream(path: str) -> bool:
    """Whether ``path`` is ``-`` (standard input) or names a pipe, a FIFO or a character
    device (``/dev/stdin``, a process substitution's ``/dev/fd/63``): read once, by content."""
    if path == "-":
        return True
    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError):
        return False
    return stat.S_ISFIFO(mode) or stat.S_ISCHR(mode)


#: what each stream gave, by its identity: a stream reads once, and a run asks more than once
#: (the files a handle file names, then the handle file)
_STREAMS: dict[tuple, bytes] = {}


def document_bytes(path: str) -> bytes:
    """The bytes of the document at ``path`` less a byte order mark: a regular file's (see
    :func:`.input_files.read_input_bytes`), or a stream's (:func:`is_stream`), read once for
    each stream and at most :data:`MAX_BYTES` and one more byte of it."""
    if not is_stream(path):
        return read_input_bytes(path)
    key = _stream_key(path)
    if key not in _STREAMS:
        _STREAMS.clear()  # one stream's bytes kept at a time: a run reads one
        _STREAMS[key] = _read_stream(path)
    return _STREAMS[key]


def _stream_key(path):
    if path == "-":
        return ("-", id(sys.stdin))  # a host that runs commands in-process swaps stdin
    info = os.stat(path)
    return (path, info.st_dev, info.st_ino)


#: seconds a pipe may stay silent (no writer yet, or a writer that sends nothing) before its
#: read is given up: a FIFO nobody writes to must not hold the run forever
STREAM_WAIT = 30.0


def _read_stream(path):
    name = "<stdin>" if path == "-" else path
    try:
        if path == "-":
            if sys.stdin is None or sys.stdin.closed:
                raise InputError("<stdin>: standard input is closed; give a file instead of '-'")
            fd = _descriptor(sys.stdin)
            data = sys.stdin.buffer.read(MAX_BYTES + 1) if fd is None else _read_fd(fd, name)
        else:
            data = _read_pipe(path, name)
    except OSError as exc:
        raise InputError(f"{name}: cannot read: {exc.strerror or exc}") from None
    if not data.strip():
        raise InputError(f"{name}: the stream is empty")
    return data[len(BOM):] if data.startswith(BOM) else data


def _read_pipe(path, name):
    """At most MAX_BYTES and one byte of a FIFO or device, waiting at most STREAM_WAIT
    seconds for each chunk: opened without blocking (a FIFO's open waits for a writer), then
    polled (on Linux a FIFO is not readable until a writer sends or closes)."""
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    try:
        return _read_fd(fd, name)
    finally:
        os.close(fd)


def _descriptor(stream):
    """The descriptor behind ``stream``, or None (a host running commands in-process gives
    a stream in memory)."""
    try:
        return stream.fileno()
    except (AttributeError, OSError, ValueError):
        return None


def _read_fd(fd, name):
    """At most MAX_BYTES and one byte from ``fd``, giving up when nothing has come for
    STREAM_WAIT seconds, the time said as it was measured (standard input waits for its
    writer as a FIFO does)."""
    poller = select.poll()
    poller.register(fd, select.POLLIN)
    chunks, total, since = [], 0, time.monotonic()
    while total <= MAX_BYTES:
        left = STREAM_WAIT - (time.monotonic() - since)
        if left <= 0 or not poller.poll(int(left * 1000) + 1):
            raise InputError(f"{name}: nothing came through it in "
                             f"{round(time.monotonic() - since, 1):g} s (a pipe nobody writes "
                             "to?); give a file")
        try:
            chunk = os.read(fd, 1 << 20)
        except BlockingIOError:
            time.sleep(0.01)  # readable for poll, not yet for read (a FIFO with no writer)
            continue
        if not chunk:
            break
        chunks.append(chunk)
        total += len(chunk)
        since = time.monotonic()
    return b"".join(chunks)


def _reason(exc):
    """What is wrong, in one line: YAML's problem ("found character '\\t' that cannot start
    any token") before its context ("while scanning for the next token"), which its first
    line holds alone."""
    problem, context = getattr(exc, "problem", None), getattr(exc, "context", None)
    if problem:
        return problem + (f" ({context})" if context else "")
    text = str(exc).strip()
    return plain(text.splitlines()[0]) if text else type(exc).__name__


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
        if isinstance(node, yaml.MappingNode):
            _duplicate_key(node, path)
        size[key] = 1 + sum(size[id(k)] for k in kids)
        depth[key] = 1 + max((depth[id(k)] for k in kids), default=0)
        if size[key] > MAX_NODES:
            raise InputError(f"{path}: expands to more than {MAX_NODES} nodes (aliases "
                             "counted where they are used)")
        if depth[key] > MAX_DEPTH:
            raise InputError(f"{path}: nested too deeply (at most {MAX_DEPTH} levels)")


def _unique(pairs, text, path):
    """A JSON object's dict, or InputError for a key given twice (json keeps the last one
    silently: a group's or a manifest's entries dropped without a word), with the line of
    its second appearance where the text shows it once more than once."""
    seen = set()
    for key, _ in pairs:
        if key in seen:
            quoted = json.dumps(key)
            at = [k for k in range(len(text)) if text.startswith(quoted, k)]
            line = f" (line {text.count(chr(10), 0, at[1]) + 1})" if len(at) == 2 else ""
            raise InputError(f"{path}: key {quoted} given twice in one object{line}; the "
                             "first would be dropped")
        seen.add(key)
    return dict(pairs)


def _duplicate_key(node, path):
    """InputError for a YAML mapping that gives a key twice (the loader keeps the last one
    silently), naming the key and the line of its second appearance. Keys are compared as
    the loader reads them, not as written: ``1``, ``0x1`` and ``01`` are one integer, ``true``
    and ``yes`` one boolean (and, in the dictionary it makes, the same key as ``1``)."""
    loader = yaml.SafeLoader("")
    seen: dict[Any, str] = {}
    for key, _ in node.value:
        if not isinstance(key, yaml.ScalarNode) or key.value == "<<":  # merges: YAML's own
            continue
        value = _key_value(loader, key)
        if value in seen:
            same = "" if seen[value] == key.value else f", the same key as {seen[value]!r}"
            raise InputError(f"{path}: key {key.value!r} given twice in one mapping (line "
                             f"{key.start_mark.line + 1}{same}); the first would be dropped")
        seen[value] = key.value


def _key_value(loader, key):
    """A scalar key node as the loader reads it (its spelling where it cannot be read)."""
    try:
        value = loader.construct_object(key)
        hash(value)
        return value
    except (yaml.YAMLError, TypeError, ValueError):
        return (key.tag, key.value)


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
