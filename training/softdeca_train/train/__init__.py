"""Training of the bundle's networks (paper 3.5, 3.6.3): SoftDECA (through the differentiable
deformation transfer), SparseSoftDECA, their dynamics, the identity encoder, the baselines of
the paper's Table 1, and the evaluation report."""
