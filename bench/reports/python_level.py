"""python_level.py's report: each package's time ÷ exactgeo's from the same arrays, and how far its distances
are from exactgeo's, as NAME.md."""

from __future__ import annotations

from pathlib import Path

from reports.tables import format_ratio, format_seconds, markdown_table


def write_markdown(path: Path, report: dict) -> None:
    peers = [p for p in report["solvers"] if p != "exactgeo"]
    lines = [
        "# Python-level comparison",
        "",
        f"Run {report['date']} by `bench/python_level.py` (see bench/README.md): one process, the same numpy arrays "
        f"(V float64, F int32) for every package, median of {report['settings']['repeat']} batches. "
        f"Load average at the start: {report['load_average']}; at the end: {report['load_average_at_end']}.",
        "",
        "Each cell is the package's time divided by exactgeo's (above 1: exactgeo is faster). exactgeo answers "
        "single sources on one thread, as the others do; the distance matrix below is timed on every core and on one. "
        "† gdist and libigl have no prepared form: they rebuild the mesh in every call.",
        "",
    ]
    for key, title in (
        ("one_call_seconds", "One call from arrays (build the mesh, distances from one source)"),
        ("prepared_seconds", "Prepared mesh (one query on a mesh built beforehand)"),
    ):
        rows = []
        for record in report["meshes"]:
            solvers = record["solvers"]
            ours = solvers["exactgeo"][key]
            cells = []
            for peer in peers:
                if peer not in solvers:
                    cells.append(None)
                    continue
                mark = " †" if key == "prepared_seconds" and solvers[peer]["rebuilds_every_call"] else ""
                cells.append(format_ratio(solvers[peer][key], ours) + mark)
            rows.append([record["mesh"], record["faces"], *cells, format_seconds(ours)])
        lines += [f"## {title}", ""]
        lines += markdown_table(["mesh", "faces", *peers, "exactgeo itself"], rows, "lr" + "r" * (len(peers) + 1))
        lines.append("")
    matrix = report["matrix"]
    ours = matrix["seconds"]["exactgeo"]
    lines += [
        f"## Distance matrix: {len(matrix['sources'])} sources × every vertex of {matrix['mesh']} "
        f"({matrix['faces']:,} faces)",
        "",
        f"exactgeo.distance_matrix on {matrix['threads']} threads against each way of getting the same rows; "
        "the others one call per source on a prepared mesh.",
        "",
    ]
    lines += markdown_table(["solver", "time ÷ exactgeo's"],
                            [[name, format_ratio(seconds, ours)] for name, seconds in matrix["seconds"].items()], "lr")
    lines += ["", f"exactgeo's own time: {format_seconds(ours)}.", ""]
    lines += local_matrix_lines(report)
    lines += [
        "## Agreement with exactgeo",
        "",
        "Largest difference over the vertices both call reachable, relative to the largest distance "
        "(Kirsanov's MMP in pygeodesic, gdist and libigl is exact; the heat method is not), and vertices one "
        "calls unreachable and the other does not.",
        "",
    ]
    rows = []
    for record in report["meshes"]:
        cells = []
        for peer in peers:
            entry = record["solvers"].get(peer)
            if entry is None:
                cells.append(None)
                continue
            disagreements = entry["reachability_disagreements"]
            cells.append(f"{entry['max_relative_difference']:.1e}"
                         + (f", {disagreements} unreachable differ" if disagreements else ""))
        rows.append([record["mesh"], *cells])
    lines += markdown_table(["mesh", *peers], rows, "l" + "r" * len(peers))
    skipped = {n: r for record in report["meshes"] for n, r in record.get("skipped", {}).items()}
    lines += [
        "",
        *(f"— {name}: skipped {reason}." for name, reason in skipped.items()),
        "",
        "## Machine and software",
        "",
    ]
    machine = report["machine"]
    lines.append(f"{machine['cpu_model']}, {machine['logical_cores']} logical cores, Python {report['python']}.")
    lines.append(", ".join(f"{name} {version}" for name, version in report["versions"].items()) + ".")
    path.write_text("\n".join(lines) + "\n")


def local_matrix_lines(report: dict) -> list[str]:
    """The local matrices' section: gdist's time ÷ exactgeo's per mesh and radius, and their agreement."""
    records = report.get("local_matrices", [])
    if not records:
        return []
    lines = [
        "## Local matrices: every vertex a source, out to a radius",
        "",
        "A sparse matrix of the distances up to `r` between every pair of vertices, from the arrays: "
        "`exactgeo.distance_matrix(exactgeo.Mesh(V, F), np.arange(n), max_distance=r)` (the mesh built in the "
        "timed call, as gdist builds its own) against `gdist.local_gdist_matrix(V, F, max_distance=r)`; `r` in "
        f"mean edge lengths; median of {report['settings']['local_repeat']} batches. The ratios are gdist's time "
        "÷ exactgeo's (above 1: exactgeo is faster). *Entries*: exactgeo's, the 0 at each source included; "
        "*only one holds*: entries one matrix holds and the other not (the 0 at each source, which gdist leaves "
        "out, not counted); *largest difference*: over the entries both hold, relative to `r`.",
        "",
    ]
    rows = []
    for record in records:
        for radius in record["radii"]:
            seconds = radius["seconds"]
            rows.append([
                record["mesh"],
                f"{record['vertices']:,}",
                f"{radius['edges']:g}",
                f"{radius['entries']:,}",
                format_seconds(seconds["exactgeo, 1 thread"]),
                format_ratio(seconds["gdist"], seconds["exactgeo, 1 thread"]),
                format_ratio(seconds["gdist"], seconds["exactgeo"]),
                f"{radius['only_ours']:,} · {radius['only_theirs']:,}",
                f"{radius['max_difference'] / radius['radius']:.1e}",
            ])
    threads = records[0]["threads"]
    lines += markdown_table(
        ["mesh", "vertices", "r (edges)", "entries", "exactgeo, 1 thread", "gdist ÷ exactgeo, 1 thread",
         f"gdist ÷ exactgeo, {threads} threads", "only one holds (exactgeo · gdist)", "largest difference ÷ r"],
        rows, "lrrrrrrrr")
    return [*lines, ""]
