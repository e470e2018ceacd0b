"""What a fork server imports before it forks srarap's worker processes (see
:func:`srarap_cli.runtime.threads.worker_processes`): the jobs' code, and the workers' signal
dispositions, which every worker forked from the server keeps.

A worker leaves SIGINT to the batch (a terminal's Ctrl-C reaches the whole group; the batch
stops the workers and reports) and dies of SIGTERM, as Dask's nanny stops its workers: with
Python's own handling each printed a traceback from wherever it was. Importing this module
anywhere else would change that process's signals: only a fork server imports it.
"""
import signal

from ...runtime.allocator import own_process
from ...runtime.signals import SIGNALS
from . import run  # noqa: F401  (imported here so that workers start with it)

own_process()  # a worker is the command's process: its allocator policy too

signal.signal(signal.SIGINT, signal.SIG_IGN)
signal.signal(signal.SIGTERM, signal.SIG_DFL)
# the server started with them held back (runtime.threads): a SIGINT that came meanwhile is
# now ignored, a SIGTERM ends it
signal.pthread_sigmask(signal.SIG_UNBLOCK, SIGNALS)
