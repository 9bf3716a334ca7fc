"""The material controls gallery and its figures: every control of p moved across its range
on the physics and on a model bundle, the change each causes, how well the model follows it
(response error) and how well a region control stays in its region (leakage)."""
