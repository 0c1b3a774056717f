"""The references of the flows beyond the conveyor front (docs/flows.md). Pure functions over
numbers, arrays and xarray objects:

  slump  a 2D gravity current released from a rectangle on a horizontal bed: Huppert's
         viscous similarity solution, and the arrested shape of a yield-stress fluid
  film   start-up from rest of a film on an incline
  user   front positions and depth or velocity profiles read from CSV files, and the errors
         of a run against them
"""
