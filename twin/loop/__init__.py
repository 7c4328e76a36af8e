"""The twin loop and its batch replay.

replay      one run × one correction method, window by window (the loop itself)
metrics     accuracy.json metrics
runfiles    one run × all methods → its output folder
batch       many runs: local processes or dask, resume, summary.json
snapshot    headless field pictures (pyvista)
report      the self-contained report.html
training    simulate_for_training: a run replayed with the window fit (training samples)
windowfit   the offline window fit that makes the training targets
"""


def __getattr__(name: str):  # noqa: ANN202 - lazy: keep `import twin.loop.x` light
    if name == "simulate_for_training":
        from twin.loop.training import simulate_for_training

        return simulate_for_training
    raise AttributeError(name)
