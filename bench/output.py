"""Write a benchmark run: ``bench.json`` (everything), ``bench.md`` (the table) and the
row 7 log-log plot ``bench_scaling.png``; every file is written atomically."""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from alte.fsutil import atomic_path
from alte.types import JSONDict, JSONMap
from bench.core import LIMITS, Result
from bench.runner import ROWS, Bench
from bench.timing import nlogn_exponent

__all__ = ["format_value", "miss_note", "plot_scaling", "render_markdown", "write_outputs"]


def format_value(value: float, unit: str) -> str:
    """A figure with its unit, sized for a table cell."""
    if value is None or not math.isfinite(value):
        return "n/a"
    if unit == "B":
        return f"{value / 2**20:.1f} MiB"
    if unit == "s":
        return f"{value:.3g} s" if value >= 1e-3 else f"{value * 1e6:.3g} us"
    if unit == "ms":
        return f"{value:.3g} ms"
    return f"{value:.3g}"


def _numbers(detail: JSONMap, key: str) -> list[float]:
    """The numbers listed under ``key`` in a row's detail (none when absent)."""
    values = detail.get(key)
    return [v for v in values if isinstance(v, int | float)] if isinstance(values, list) else []


def _named_numbers(detail: JSONMap, key: str) -> dict[str, float]:
    """The numbers by name under ``key`` in a row's detail (none when absent)."""
    values = detail.get(key)
    if not isinstance(values, Mapping):
        return {}
    return {k: v for k, v in values.items() if isinstance(v, int | float)}


def miss_note(result: Result) -> str:
    """One sentence on a missed target: by how much."""
    if result.met is not False:
        return ""
    if result.unit == "exponent":
        return f"row {result.row} {result.case}: exponent {result.ours:.2f} vs n log n's " \
               f"{result.peer:.2f}"
    if "grid_wall_h" in result.detail:
        return (f"row {result.row} {result.case}: the grid's estimated wall time "
                f"{result.detail['grid_wall_h']:.2f} h on {result.detail['workers']} cores, "
                f"{result.target}")
    if "ratio" not in result.target:  # an absolute target, e.g. "< 100 ms"
        return f"row {result.row} {result.case}: {result.ours:.3g} {result.unit}, " \
               f"target {result.target}"
    limit = result.detail.get("limit", LIMITS[result.row])
    bound = float(limit) if isinstance(limit, int | float) else LIMITS[result.row]
    return (f"row {result.row} {result.case}: ratio {result.ratio:.3g}, target <= {bound:.3g} "
            f"(missed by {result.ratio / bound:.2f}x)")


def _line(result: Result) -> str:
    met = {True: "yes", False: "**no**", None: "-"}[result.met]
    extra = ""
    if "jaccard" in result.detail:
        extra = f" (Jaccard {result.detail['jaccard']:.5f})"
    return (f"| {result.row} | {result.case}{extra} | {format_value(result.ours, result.unit)} | "
            f"{format_value(result.peer, result.unit)} | {result.ratio:.3g} | {result.target} | "
            f"{met} |")


def _machine(bench: Bench) -> list[str]:
    m, cfg = bench.machine, bench.config
    return [f"- machine: {m['cpu']}, {m['cores']} cores ({m.get('cores_usable')} usable), "
            f"{m['memory_gib']} GiB; load average at start {m['load_avg_1_5_15']}, at end "
            f"{m.get('load_avg_end')}",
            f"- software: python {m['python']}, numpy {m['numpy']}, scipy {m['scipy']}, "
            f"numba {m['numba']}, open3d {m['open3d']}, pyoctomap {m['pyoctomap']}",
            f"- run: {bench.started}, {bench.seconds:.0f} s, {'quick' if cfg.quick else 'full'} "
            f"mode, median of {cfg.repeats} repeats after {cfg.warmup} warm-up, ours and peer "
            f"interleaved; frames for rows 1/2/4: {cfg.frames or 'all'} (row 5: all); "
            f"peak RSS {m.get('peak_rss_gib')} GiB"]


def _report_share_lines(results: list[Result]) -> list[str]:
    out = []
    for r in (r for r in results if r.row == 8 and r.detail.get("shares")):
        out += ["", "Row 8 stage shares of the report's wall time:", "",
                "| stage | share |", "|---|---|"]
        out += [f"| {k} | {v:.1%} |" for k, v in _named_numbers(r.detail, "shares").items()]
    return out


def _scaling_lines(results: list[Result]) -> list[str]:
    out = []
    for r in (r for r in results if r.row == 7):
        sizes = ", ".join(f"{n:.0e}: {s:.3g} s" for n, s in zip(
            _numbers(r.detail, "sizes"), _numbers(r.detail, "seconds"), strict=True))
        skipped = ", ".join(f"{int(n):.0e} (predicted {s:.0f} s)"
                            for n, s in _named_numbers(r.detail, "skipped_predicted_s").items())
        out.append(f"- {r.case}: {sizes}" + (f"; skipped {skipped}" if skipped else ""))
    return (["", "Row 7 timings (plot: bench_scaling.png):", "", *out]) if out else []


def _grid_estimate_lines(results: list[Result]) -> list[str]:
    out = [f"- {r.case}: {d['sample_runs']} runs in {d['sample_cpu_s']:.1f} CPU s, inputs "
           f"prepared in {d['prepare_cpu_s_per_input']:.1f} CPU s each; the grid's "
           f"{d['grid_runs']:,} runs on {d['grid_inputs']} inputs: {d['grid_cpu_h']:.2f} CPU h, "
           f"{d['grid_wall_h']:.2f} h on {d['workers']} cores ({d['grid_runs_per_core_s']:.2f} "
           f"runs per core-second); today's path run by run: {d['peer_runs']} runs in "
           f"{d['peer_cpu_s']:.1f} CPU s"
           for r in results if r.row == 13 for d in (r.detail,)]
    return (["", "Row 13 estimates (stratified sample of map groups, CPU seconds):", "",
             *out]) if out else []


def render_markdown(bench: Bench) -> str:
    """The report: machine, the table, missed targets, failed rows, row 7/8 details."""
    lines = ["# alte benchmark", "", *_machine(bench), "",
             "| # | case | ours | peer | ratio ours/peer | target | met |",
             "|---|---|---|---|---|---|---|"]
    lines += [_line(r) for r in bench.results]
    misses = [miss_note(r) for r in bench.results if r.met is False]
    if misses:
        lines += ["", "Targets missed (profiles and causes: docs/results/bench.md, "
                  "docs/design-notes/bench.md):", ""]
        lines += [f"- {m}" for m in misses]
    if bench.errors:
        lines += ["", "Rows that failed:", ""]
        lines += [f"- row {n} ({ROWS[n][0]}): {msg}" for n, msg in bench.errors.items()]
    return "\n".join([*lines, *_scaling_lines(bench.results), *_report_share_lines(bench.results),
                      *_grid_estimate_lines(bench.results), ""])


def plot_scaling(results: list[Result], path: Path) -> Path | None:
    """Log-log seconds vs points of every row 7 case, exponents in the legend."""
    cases = [r for r in results if r.row == 7 and len(_numbers(r.detail, "sizes")) >= 2]
    if not cases:
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 5))
    for r in cases:
        ax.loglog(_numbers(r.detail, "sizes"), _numbers(r.detail, "seconds"), "o-",
                  label=f"{r.case.split()[0]} (exponent {r.ours:.2f})")
    n = np.asarray(sorted({s for r in cases for s in _numbers(r.detail, "sizes")}), float)
    ref = n * np.log(n) / (n[0] * np.log(n[0])) * min(_numbers(r.detail, "seconds")[0]
                                                      for r in cases)
    ax.loglog(n, ref, "k--", label=f"n log n (exponent {nlogn_exponent(n):.2f})")
    ax.set(xlabel="points", ylabel="seconds (median)", title="Row 7: scaling")
    ax.legend(fontsize=8)
    ax.grid(True, which="both", alpha=0.3)
    with atomic_path(path, overwrite=True) as tmp:
        fig.savefig(tmp, format="png", dpi=120)
    plt.close(fig)
    return path


def write_outputs(bench: Bench, reports_dir: str | Path) -> dict[str, Path]:
    """Write bench.json, bench.md and (with row 7 data) bench_scaling.png under ``reports_dir``."""
    out = Path(reports_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths: dict[str, Path] = {"json": out / "bench.json", "md": out / "bench.md"}
    record: JSONDict = bench.as_dict()
    with atomic_path(paths["json"], overwrite=True) as tmp:
        tmp.write_text(json.dumps(_finite(record), indent=2, default=_jsonable) + "\n")
    with atomic_path(paths["md"], overwrite=True) as tmp:
        tmp.write_text(render_markdown(bench))
    png = plot_scaling(bench.results, out / "bench_scaling.png")
    if png is not None:
        paths["png"] = png
    return paths


def _jsonable(value: object) -> object:
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    return str(value)


def _finite(value: object) -> object:
    """NaN and inf become null, so bench.json is strict JSON."""
    if isinstance(value, dict):
        return {str(k): _finite(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_finite(v) for v in value]
    if isinstance(value, float | np.floating) and not math.isfinite(value):
        return None
    return value
