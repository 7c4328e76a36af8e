"""The training report written beside a model: JSON figures and a self-contained HTML page
with loss curves, the R² table (both configurations) and predicted-vs-target plots."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from twin.correction.features import OUTPUTS, TARGET_UNITS, kind_of
from twin.correction.training import TrainingResult
from twin.io.atomic import write_json, write_text
from twin.io.figures import new_figure, png_bytes
from twin.io.html_pages import png_data_uri, render_page


def report_paths(model_path: str | Path) -> tuple[Path, Path]:
    """(JSON, HTML) report paths beside the model: MODEL.report.json, MODEL.report.html."""
    p = Path(model_path)  # `parent /`: with_name refused '.' (--out '') with a ValueError
    return p.parent / (p.name + ".report.json"), p.parent / (p.name + ".report.html")


def _figure_png(fig: Any) -> bytes:
    return png_bytes(fig, dpi=90)


def _plots(results: dict[str, TrainingResult]) -> list[tuple[str, bytes]]:
    images = []
    fig = new_figure(figsize=(16, 3.4))
    axes = fig.subplots(1, 4)
    for ax, output in zip(axes, OUTPUTS, strict=True):
        for name, res in results.items():
            h = res.outputs[output].history
            ax.semilogy(h.train_mse, label=f"{name} train")
            ax.semilogy(h.test_mse, "--", label=f"{name} test")
        ax.set_title(output)
        ax.set_xlabel("epoch")
        ax.set_ylabel("MSE (scaled)")
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    images.append(("Loss curves (training and held-out 20 %)", _figure_png(fig)))

    for name, res in results.items():
        fig = new_figure(figsize=(16, 3.6))
        axes = fig.subplots(1, 4)
        for ax, output in zip(axes, OUTPUTS, strict=True):
            r = res.outputs[output]
            ax.plot(r.test_target, r.test_predicted, ".", ms=3)
            lo = float(np.nanmin(r.test_target))
            hi = float(np.nanmax(r.test_target))
            ax.plot([lo, hi], [lo, hi], "k-", lw=0.8)
            ax.set_title(f"{output}  R²={r.r2_value:.4f}")
            unit = TARGET_UNITS[kind_of(output)]
            ax.set_xlabel(f"target [{unit}]")
            ax.set_ylabel(f"predicted [{unit}]")
        fig.tight_layout()
        images.append((f"Predicted vs target, held-out samples ({name})", _figure_png(fig)))
    return images


def write_report(
    model_path: str | Path, results: dict[str, TrainingResult], chosen: str
) -> tuple[Path, Path]:
    """Write MODEL.report.json and MODEL.report.html; `results` maps configuration name to
    its training result, `chosen` names the one saved as the model."""
    json_path, html_path = report_paths(model_path)
    summary = {
        "model": Path(model_path).name,
        "chosen_config": chosen,
        "configs": {
            name: {
                "seconds": res.seconds,
                "r2": res.r2_table(),
                "final_train_mse": {o: float(r.history.train_mse[-1])
                                    for o, r in res.outputs.items()},
                "final_test_mse": {o: float(r.history.test_mse[-1])
                                   for o, r in res.outputs.items()},
            }
            for name, res in results.items()
        },
        "metadata": results[chosen].model.metadata,
    }
    write_json(json_path, summary)

    configs = [{"name": n, "saved": n == chosen, "time": f"{n} {r.seconds:.1f} s"}
               for n, r in results.items()]
    rows = [{"output": output,
             "cells": [cell for res in results.values() for cell in (
                 f"{res.outputs[output].r2_value:.5f}", f"{res.outputs[output].r2_factor:.4f}",
                 res.outputs[output].history.epochs)]}
            for output in OUTPUTS]
    images = [{"title": title, "src": png_data_uri(png)} for title, png in _plots(results)]
    page = render_page("training_report.html.j2", model_name=Path(model_path).name,
                       meta=results[chosen].model.metadata, configs=configs, rows=rows,
                       images=images)
    write_text(html_path, page)
    return json_path, html_path

