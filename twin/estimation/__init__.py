"""Online estimation: joint state–parameter estimation with an ensemble Kalman filter.

- `parameters`: the estimated log-factors (priors, random walk, bounds), applying them to
  the boundary conditions, their tangent operators.
- `ensemble`: mean + anomalies of [field; log-factors], random walk, spread cap.
- `analysis`: the ETKF measurement update.
- `forecast`: one window for the ensemble (FEM mean, tangent-linear members).
- `method`: the `estimator` correction method (design, sensitivity study, deck relation).
- `sensitivity`: the sensitivity and observability study behind the parameter choice.
"""
