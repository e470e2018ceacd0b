"""Files in and out: mesh formats (``mesh``), handle files and keyframes (``handles``), YAML/JSON
documents, solve logs, and the reading of user inputs with one-line errors.

Rule: imports ``solver`` (settings and rotations, to parse handle files) and ``runtime``; never
``tasks`` or ``cli``.
"""
