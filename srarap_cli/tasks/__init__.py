"""What a command does, as plain functions of meshes and handles: deform a mesh (``pipeline``),
animate, batch, compare, bench, render, preview, distortion, samples.

Rule: imports ``io``, ``solver`` and ``runtime``; never ``cli`` (no Click, no exit codes, no
printing of summaries: those belong to the command line).
"""
