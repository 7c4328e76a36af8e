"""The twin loop and its batch replay.

replay       one run × one correction method, window by window (the loop itself)
metrics      accuracy.json metrics
runfiles     one run × all methods → its output folder
batch        many runs: local processes or dask, resume, summary.json
snapshot     headless field pictures (pyvista)
report       the self-contained report.html
training     training_simulator: a run replayed for the networks' training samples
target_rules TargetRule: how the training targets are made (fit | ratio)
windowfit    the offline window fit that makes the training targets
"""

