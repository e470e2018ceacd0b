"""Local steps: given deformed positions, find the cell rotors.

``membrane`` builds the per-vertex 4x4 matrices every method shares; ``linear`` is the
paper's one-solve rotor system (section 6).
"""
