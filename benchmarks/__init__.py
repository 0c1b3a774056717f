"""The maintained benchmarks: each is a module run from the repository root,

    python -m benchmarks.NAME [--quick] [--help]

``--quick`` is each one's smallest mode (seconds to a minute). ``python -m benchmarks.report``
runs them all and writes benchmarks/RESULTS.md. The options, timing, host description and
case loading they share are in ``benchmarks.common``.
"""
