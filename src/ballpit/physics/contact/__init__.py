"""Contact: what touching does (contact rows on the one contact model, the Gauss–Seidel and Jacobi
solves, impacts, the resting solve, penetration removal, the soft step's substeps, the energy guards).
Imports the core, dynamics and collision."""
