"""Every table the code generates, written where the docs show it: the README's settings table
(from the settings table, ``srarap_cli.cli.options.markdown_table``) and format table (from
the format registry, ``srarap_cli.io.mesh.meshio_formats.markdown_table``), the exit codes
(the README's and ``docs/reference/exit-codes.md``, from ``srarap_cli.runtime.exit_codes``),
the warning codes
(``docs/reference/warnings.md``, from ``srarap_cli.runtime.warning_codes``), and the handle
files' JSON Schema (``docs/handles.schema.json``, ``srarap_cli.io.handles.schema``).

Run from the repository root after changing a setting, a format or the handle-file schema:

    python docs/make_tables.py            # rewrite what changed
    python docs/make_tables.py --check    # exit 1, naming the stale files, if any is stale

tests/test_readme.py runs ``--check``.
"""
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
README = os.path.join(ROOT, "README.md")
SCHEMA = os.path.join(HERE, "handles.schema.json")
WARNINGS = os.path.join(HERE, "reference", "warnings.md")
EXIT_CODES = os.path.join(HERE, "reference", "exit-codes.md")


def replace_table(text: str, table: str) -> str:
    """``text`` with the Markdown table that has ``table``'s header line replaced by it."""
    header = table.splitlines()[0]
    start = text.index(header)
    end = text.find("\n\n", start)
    end = len(text) if end < 0 else end + 1
    return text[:start] + table + text[end:]


def generated() -> dict[str, str]:
    """path -> the content it should have."""
    from srarap_cli.cli.options import markdown_table as settings_table
    from srarap_cli.io.handles.schema import schema_text
    from srarap_cli.io.mesh.meshio_formats import markdown_table as formats_table
    from srarap_cli.runtime.exit_codes import markdown_table as exit_table
    from srarap_cli.runtime.warning_codes import markdown_table as warnings_table

    with open(README, encoding="utf-8") as fh:
        readme = fh.read()
    for table in (settings_table(), formats_table(), exit_table(advice=False)):
        readme = replace_table(readme, table)
    with open(WARNINGS, encoding="utf-8") as fh:
        codes = replace_table(fh.read(), warnings_table())
    with open(EXIT_CODES, encoding="utf-8") as fh:
        exits = replace_table(fh.read(), exit_table(advice=True))
    return {README: readme, SCHEMA: schema_text(), WARNINGS: codes, EXIT_CODES: exits}


def main(argv: list[str]) -> int:
    stale = []
    for path, text in generated().items():
        with open(path, encoding="utf-8") as fh:
            if fh.read() == text:
                continue
        stale.append(os.path.relpath(path, ROOT))
        if "--check" not in argv:
            with open(path, "w", encoding="utf-8") as fh:
                fh.write(text)
    if stale:
        print(("stale: " if "--check" in argv else "wrote: ") + ", ".join(stale)
              + ("; run: python docs/make_tables.py" if "--check" in argv else ""))
    return 1 if stale and "--check" in argv else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
