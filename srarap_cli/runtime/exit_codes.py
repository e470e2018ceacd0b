"""Exit codes of the ``srarap`` command (documented in the README)."""
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
