"""Reference solutions of flows other than the conveyor front (docs/flows.md). Pure functions
over numbers and arrays:

  slump  a 2D gravity current released from a rectangle on a horizontal bed: Huppert's
         viscous similarity solution, and the arrested shape of a yield-stress fluid
  film   start-up from rest of a film on an incline

Not yet used by the campaign (Snakefile, workflow/rules) or the solver.
"""
