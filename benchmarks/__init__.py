"""Benchmarks, run by hand (`python -m benchmarks derive|integrate|load|page ...`): not part
of the engine, not in the wheel. Results and how to reproduce them: docs/benchmarks.md."""
