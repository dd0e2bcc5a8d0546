"""Benchmarks run by ``seawatch bench NAME``; each reports ratios against a reference
measured in the same run (never absolute timings alone)."""
