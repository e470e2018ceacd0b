"""SIGTERM as an exception, installed before anything slow is imported, so that a signal at
any moment ends the run with one line and the documented code (SIGINT already raises
KeyboardInterrupt)."""
import signal
import threading


class Terminated(BaseException):
    """SIGTERM arrived; raised so that cleanup (temporary files) runs on the way out."""


def _on_sigterm(_signum, _frame):
    raise Terminated()


def install():
    """Route SIGTERM to :class:`Terminated` (main thread only: signals go there)."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, _on_sigterm)
