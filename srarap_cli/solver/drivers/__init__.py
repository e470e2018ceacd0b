"""Drivers: how the next iterate is chosen and when a solve stops.

A driver is ``driver(step, state, monitor) -> State``: it calls ``step`` (the fixed-point map
of one local/global iteration) from the start ``state`` and hands every iterate it accepts to
``monitor.record``, which keeps the log, calls the callback, checks for non-finite values and
answers whether to stop (tolerance, iteration cap, time limit). :data:`DRIVERS` maps names to
drivers; :func:`register` adds one.
"""
from .monitor import Monitor
from .registry import ACCEL_DRIVERS, CORRECTED, DRIVERS, corrected_driver, register

__all__ = ["ACCEL_DRIVERS", "CORRECTED", "DRIVERS", "Monitor", "corrected_driver", "register"]
