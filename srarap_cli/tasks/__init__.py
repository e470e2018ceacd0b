"""What a command does, callable from Python, in wings: ``deform``, ``animate``,
``comparison``, ``pictures``, ``bench``, ``batch`` (each a package with one entry: a frozen job,
a ``run_*`` function and its outcome), and what they share (``pipeline``, ``preflight``,
``job_status``, ``reports``, ``fingerprint``, ``info``, ``rigid_parts``, ``distortion``,
``samples`` and ``sample_files``, ``api``). A wing reaches another only through its package.

Rule: imports ``io``, ``solver`` and ``runtime``; never ``cli`` (no Click, no exit codes, no
printing of summaries: those belong to the command line).
"""
