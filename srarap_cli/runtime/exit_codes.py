"""Exit codes of the ``srarap`` command: the names the code uses and :data:`TABLE`, from which
``docs/make_tables.py`` writes the README's and the docs' tables."""
OK = 0
INTERNAL_ERROR = 1
USAGE = 2  # click's own code for bad options
NOT_CONVERGED = 3
INVALID_INPUT = 4
NUMERICAL_FAILURE = 5
OUTPUT_ERROR = 6
BEYOND_TOLERANCE = 7  # srarap compare: the meshes differ by more than --tol
BATCH_FAILED = 8  # srarap batch: a job failed or regressed
INTERRUPTED = 130  # SIGINT (Ctrl-C)
BROKEN_PIPE = 141  # the reader of standard output went away (as a process killed by SIGPIPE)
TERMINATED = 143  # SIGTERM

#: (codes, what they mean, what to do) per row of the documented tables
TABLE = (
    ((OK,), "done: converged, output written", ""),
    ((INTERNAL_ERROR,), "internal error (a bug)", "report it with the `srarap --debug ...` "
                                          "traceback"),
    ((USAGE,), "usage error: a bad or non-finite option, an unsupported extension, a bad frame "
               "pattern", "see `srarap COMMAND --help`"),
    ((NOT_CONVERGED,), "not converged: the log is written, the mesh is not (`deform`, `batch`); "
                       "an animation stops before the frame; `animate --iters-per-frame` (a "
                       "fixed budget) and `--tol 0` (exactly `--max-iter` iterations) exit 0",
     "the line says which test failed and what to try: raise `--max-iter`, `--multires "
     "auto`, loosen `--tol`; `--keep-unconverged` writes the result anyway"),
    ((INVALID_INPUT,), "invalid input: a file missing, unreadable or invalid (a mesh of no "
                       "format srarap reads, a handle file given as the mesh: \"mesh and "
                       "handles swapped?\"); an output that is an input; not enough memory; a "
                       "warning under `--strict`",
     "the line names the file, group and field; `srarap info MESH HANDLES` checks a handle "
     "file without solving"),
    ((NUMERICAL_FAILURE,), "numerical failure: non-finite energy, a singular system",
     "degenerate geometry (coincident or collinear vertices, zero-area triangles); a "
     "connected part with no constrained vertex is not one: it stays at rest, with a warning"),
    ((OUTPUT_ERROR,), "output error: a read-only folder, a file where a folder should be, a "
                      "full disk, an output that is a folder",
     "nothing was written or replaced (missing folders are made, and removed again on a "
     "failure)"),
    ((BEYOND_TOLERANCE,), "`compare`: beyond `--tol` (or another gate: `--beyond-tol`, "
                          "`--p95`, `--p99`)", "`--update` writes A to B when B is the "
                                               "golden, `--accept` exits 0 then"),
    ((BATCH_FAILED,), "`batch`: a job failed, regressed against its golden mesh or has no "
                      "golden; `compare --update`: B was missing and is written",
     "see `summary.csv`: each job's `exit_code` is the code `srarap deform` gives for the same "
     "outcome"),
    ((INTERRUPTED, TERMINATED), "interrupted (SIGINT), terminated (SIGTERM); the line says "
                                "what had been written",
     "`animate --resume` continues; `batch` stops its workers within seconds and writes its "
     "summary, the unfinished jobs marked `interrupted` (a rerun solves only those)"),
    ((BROKEN_PIPE,), "the reader of standard output went away (`... -o - \\| head`)", ""),
)


def markdown_table(advice: bool) -> str:
    """The codes as a Markdown table: code and meaning (the README), and what to do
    (``advice``: the docs' exit-code page)."""
    rows = ["| code | meaning | what to do |" if advice else "| code | meaning |",
            "|---|---|---|" if advice else "|---|---|"]
    for codes, meaning, todo in TABLE:
        code = ", ".join(map(str, codes))
        rows.append(f"| {code} | {meaning} | {todo} |" if advice else f"| {code} | {meaning} |")
    return "\n".join(rows) + "\n"
