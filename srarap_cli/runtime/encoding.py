"""Text srarap writes (reports, summaries, logs, standard output) as UTF-8 bytes, whatever
names it holds: a file name the shell allows may be bytes that are not UTF-8 (Python holds
them as lone surrogates), and a JSON job name may hold a lone surrogate itself. Such
characters are written out visibly (``\\udcff``) instead of failing the run."""


def utf8(text: str) -> bytes:
    r"""``text`` as UTF-8, lone surrogates written out.

    Examples
    --------
    >>> utf8("caf\xe9 a\udcffb")
    b'caf\xc3\xa9 a\\udcffb'
    """
    return text.encode("utf-8", "backslashreplace")
