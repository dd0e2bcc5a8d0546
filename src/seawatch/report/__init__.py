"""Tables, plots and reports of seawatch results (matplotlib with the Agg backend, no GUI).

Available: :mod:`seawatch.report.air_range_plot` (range error against true range for
the ``air-range`` scenario).
"""
