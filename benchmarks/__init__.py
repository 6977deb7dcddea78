"""Benchmarks and peer methods (run as scripts or ``python -m benchmarks.NAME``)."""
