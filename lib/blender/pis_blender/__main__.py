"""`python3 -m pis_blender SCENE.blend -o SET_DIR [--spp N] [--points N] [--seed S] [--denoise auto|on|off] [--json]`: the add-on headless,
with Blender's `bpy` module (PyPI `bpy`, Python 3.11). The .blend's PIS settings say what to
render; --spp replaces its samples."""

import argparse
import json
import os
import sys


# The tools' exit codes (README.md): bad settings, I/O, not supported.
EXIT_USAGE, EXIT_IO, EXIT_UNSUPPORTED = 1, 2, 5


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python3 -m pis_blender", description=__doc__.split("\n\n")[0])
    parser.add_argument("blend", help="the .blend file, its PIS settings set (Properties > Render > PIS set)")
    parser.add_argument("-o", "--output", required=True, help="the set folder to write")
    parser.add_argument("--spp", type=int, help="Cycles samples per pixel (default: the file's)")
    parser.add_argument("--points", type=int, metavar="N", help="render only the first N parameter points (in linear order, last dimension fastest)")
    parser.add_argument("--seed", type=int, help="Cycles' seed series (default: the file's); another seed renders an independent set")
    parser.add_argument(
        "--denoise",
        choices=("auto", "on", "off"),
        help="render two halves with the denoiser's guides and join them with `pis-trace denoise` into a set with denoised twins; auto: when pis-trace is found (default: the file's setting, auto unless changed)",
    )
    parser.add_argument("--pis-trace", metavar="PATH", help="the pis-trace program that joins the halves (default: the file's, else pis-trace on the PATH)")
    parser.add_argument("--keep-halves", action="store_true", help="a denoised set: leave its two halves in SET_DIR/.halves (to join again with pis-trace denoise)")
    parser.add_argument("--json", action="store_true", help="print the report as JSON")
    args = parser.parse_args(argv)
    if args.points is not None and args.points < 1:
        print(f"pis_blender: --points {args.points}: give at least 1", file=sys.stderr)
        return EXIT_USAGE
    # Blender and its glTF exporter write their logs to standard output: they go to standard
    # error, and standard output carries the report alone.
    sys.stdout.flush()
    report_out = os.fdopen(os.dup(1), "w")
    os.dup2(2, 1)
    try:
        import bpy
    except ImportError:
        print("pis_blender: Blender's bpy module is not installed (python3 -m pip install bpy==4.5.4)", file=sys.stderr)
        return EXIT_UNSUPPORTED
    import pis_blender
    from pis_blender import scene_file, space

    pis_blender.register()
    try:
        bpy.ops.wm.open_mainfile(filepath=args.blend)
    except RuntimeError as e:
        print(f"pis_blender: {args.blend}: {e}", file=sys.stderr)
        return EXIT_IO
    scene = bpy.context.scene
    if args.spp is not None:
        scene.pis.spp = args.spp
    if args.seed is not None:
        scene.pis.seed = args.seed
    if args.denoise is not None:
        scene.pis.denoise = args.denoise.upper()
    if args.pis_trace is not None:
        scene.pis.pis_trace = args.pis_trace
    try:
        report = pis_blender.export_set(scene, args.output, progress=lambda line, _done: print(line, file=sys.stderr, flush=True), keep_halves=args.keep_halves, points=args.points)
    except space.SpaceError as e:
        print(f"pis_blender: {args.blend}: the parameter space: {e}", file=sys.stderr)
        return EXIT_USAGE
    except scene_file.ExportError as e:
        print(f"pis_blender: {args.blend}: {e}", file=sys.stderr)
        return EXIT_UNSUPPORTED
    except OSError as e:
        print(f"pis_blender: {args.output}: {e}", file=sys.stderr)
        return EXIT_IO
    if args.json:
        print(json.dumps(report), file=report_out)
    else:
        roles = ", ".join(f"{o['name']} ({o['role']})" for o in report["objects"])
        print(f"{report['set']}: {report['points']} points, {report['renders']} Cycles renders, {report['seconds']} s", file=report_out)
        print(f"objects: {roles}", file=report_out)
        for note in report.get("notes", []):
            print(f"note: {note}", file=report_out)
        if "denoised" in report:
            d = report["denoised"]
            print(f"denoised: {d['denoiser']}, {report['spp']} spp from two halves; {d['denoised_layers']} layers denoised, {len(d['kept_raw'])} kept raw", file=report_out)
    report_out.flush()
    return 0


if __name__ == "__main__":
    code = main()
    # bpy can hang in its exit handlers; every file is written, so leave at once.
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)
