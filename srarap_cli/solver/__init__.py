"""The paper's method (linear-time SR-ARAP): settings, operators, energy, the local and global
steps, starts, drivers (outer iterations), multiresolution, and :class:`Deformer`.

Rule: imports only ``runtime`` (and numpy, scipy, libigl); never files, handle files, tasks or
the command line. Everything a ``Deformer`` needs is here; it takes arrays and returns arrays.
Subpackages: ``local_step/`` (one module per rotor fit), ``starts/`` (first iterates),
``drivers/`` (plain and Anderson iterations, the stopping test), ``multires/`` (section 7).
"""
