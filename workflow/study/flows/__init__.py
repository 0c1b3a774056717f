"""The flows a campaign runs (docs/flows.md), one module each, every one a ``base.Flow`` that
``study.registry`` finds by the campaign's ``flow`` key:

  conveyor       the paper's conveyor-belt front (its metrics, verdict and report: study.metrics,
                 study.campaign, study.verdict, study.report, study.figures)
  slump          a release from a rectangle: Huppert's similarity front, or the arrested shape
  film           start-up from rest of a film on an incline
  user           any scene file against the user's CSV reference data

What the three scene flows share: ``scene`` (keys, grid, numerics, reduction, report),
``scene_figures``, ``runs`` (sequences over dp, convergence, trust), ``measure`` (the front,
depth and velocity profiles of a run's snapshots) and ``scores`` (errors with their sampling
errors). Their references are in study.references.
"""
