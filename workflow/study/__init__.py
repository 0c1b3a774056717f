"""The study: case grid, reference solution, metrics, campaign dataset, figures, report.

Pure functions over plain data and xarray objects; the Snakemake rules call them through
``python -m study``. Importable as ``study`` (source under workflow/study).
"""
