"""Process plumbing, the bottom layer: errors and their exit codes, signals, threads, memory and
size limits, all-or-nothing file commits.

Rule: imports nothing else of srarap; every other layer may import it. No numerics here.
"""
