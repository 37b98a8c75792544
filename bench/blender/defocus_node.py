"""Defocuses an all-in-focus EXR (R, G, B + Z) with Blender's compositor Defocus node, for comparison.

Run:  blender -b --factory-startup -t 2 --python bench/blender/defocus_node.py -- \
          --image DIR/pinhole.exr --fstop 1.4 --focus 3 --out DIR/blender_defocus.exr --threads 2

--fstop is the physical f-number N of a 50 mm lens on a 36 mm wide sensor (the camera of
make_reference.py). The Defocus node's own "f_stop" is not that number: its blur radius in pixels is
(source/blender/compositor/operations/COM_ConvertDepthToRadiusOperation.cc, Blender 3.4)

    r = 0.5 |A (S (1/M - 1/z) - 1)|,   A = f_mm / (2 F aspect s_mm),   S = 2 f_mm min(W, H) / s_mm

with F the node's f_stop, z the Z input (scene units, metres here), M the scene camera's focus
distance, aspect = min(W, H) / max(W, H), s_mm the camera's sensor size (sensor_width unless the fit
is vertical). For a landscape image A S = f_mm^2 W / (F s_mm^2), while Cycles' thin lens (aperture
radius f_m / (2 N), fixed field of view) blurs a point at z to the radius
0.5 (f_m / N) |1/M - 1/z| f_mm W / s_mm. The two agree when F = N * 1000 / s_mm (f in mm vs m), so
this script sets F = N * 1000 / 36 = 27.8 N (the node's F is capped at 128, i.e. N <= 4.6). The
remaining "- 1" term adds 0.5 A < 0.02 px. --node-fstop sets F directly instead.

Prints the wall time of the compositing call alone (bpy.ops.render.render, Blender start-up and
file writing excluded) as `defocus_seconds=<x>`.
"""
import argparse
import math
import os
import sys
import time

import bpy

FOCAL_LENGTH_MM = 50.0
SENSOR_WIDTH_MM = 36.0
NODE_FSTOP_MAX = 128.0  # the Defocus node's hard limit on f_stop


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="defocus_node.py", description=__doc__.splitlines()[0])
    p.add_argument("--image", required=True, help="all-in-focus EXR with R, G, B and Z (planar metres)")
    p.add_argument("--fstop", type=float, required=True, help="physical f-number N (> 0)")
    p.add_argument("--focus", type=float, required=True, help="focus distance M, metres (> 0)")
    p.add_argument("--out", required=True, help="output EXR (R, G, B float32)")
    p.add_argument("--threads", type=int, default=0, help="compositor threads, 0 = all (also pass blender -t)")
    p.add_argument("--max-blur", type=float, default=200.0,
                   help="node blur_max: largest blur radius, px (default 200; costs nothing above the "
                        "largest radius in the image)")
    p.add_argument("--threshold", type=float, default=1.0,
                   help="node threshold, px: radii <= this stay sharp, up to twice it are blended (default 1, "
                        "Blender's)")
    p.add_argument("--node-fstop", type=float, default=None,
                   help="pass this as the node's f_stop instead of N * 1000 / sensor width")
    p.add_argument("--execution-mode", choices=["TILED", "FULL_FRAME"], default="TILED",
                   help="compositor execution model (Blender 3.4 default TILED)")
    p.add_argument("--repeat", type=int, default=1,
                   help="composite this many times; defocus_seconds is the fastest run")
    a = p.parse_args(argv)
    if not a.fstop > 0 or not a.focus > 0:
        p.error("--fstop and --focus must be > 0")
    if a.repeat < 1:
        p.error("--repeat must be >= 1")
    return a


def main():
    args = parse_args()
    node_fstop = args.node_fstop if args.node_fstop is not None else args.fstop * 1000.0 / SENSOR_WIDTH_MM
    if not 0 < node_fstop <= NODE_FSTOP_MAX:
        sys.exit("defocus_node.py: node f_stop %.4g (from --fstop %.4g) is outside Blender's (0, 128]; "
                 "the node cannot blur this little" % (node_fstop, args.fstop))

    scene = bpy.context.scene
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)

    # The node reads focal length, sensor size and focus distance from the scene camera.
    cam_data = bpy.data.cameras.new("camera")
    cam_data.lens = FOCAL_LENGTH_MM
    cam_data.sensor_width = SENSOR_WIDTH_MM
    cam_data.sensor_fit = "HORIZONTAL"
    cam_data.dof.use_dof = True
    cam_data.dof.focus_distance = args.focus
    cam = bpy.data.objects.new("camera", cam_data)
    scene.collection.objects.link(cam)
    scene.camera = cam

    img = bpy.data.images.load(os.path.abspath(args.image))
    img.colorspace_settings.name = "Linear"
    width, height = img.size[0], img.size[1]
    _ = img.pixels[0]  # load the file now, outside the timed call

    scene.render.resolution_x = width
    scene.render.resolution_y = height
    scene.render.resolution_percentage = 100
    scene.render.use_compositing = True
    scene.render.use_sequencer = False
    if args.threads > 0:
        scene.render.threads_mode = "FIXED"
        scene.render.threads = args.threads
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"

    scene.use_nodes = True
    tree = scene.node_tree
    tree.nodes.clear()
    tree.execution_mode = args.execution_mode
    tree.render_quality = "HIGH"
    tree.use_opencl = False
    src = tree.nodes.new("CompositorNodeImage")
    src.image = img
    defocus = tree.nodes.new("CompositorNodeDefocus")
    defocus.bokeh = "CIRCLE"
    defocus.angle = 0.0
    defocus.use_gamma_correction = False
    defocus.f_stop = node_fstop
    defocus.blur_max = args.max_blur
    defocus.threshold = args.threshold
    defocus.use_preview = False  # the Python default is True: a low-quality (every 3rd pixel) preview
    defocus.use_zbuffer = True   # the Python default is False: Z would be read as a radius
    out = tree.nodes.new("CompositorNodeComposite")
    out.use_alpha = False
    tree.links.new(src.outputs["Image"], defocus.inputs["Image"])
    tree.links.new(src.outputs["Depth"], defocus.inputs["Z"])
    tree.links.new(defocus.outputs["Image"], out.inputs["Image"])

    # Blur radii the node will use (its formula, before its Gaussian smoothing of the radius map).
    aspect = min(width, height) / max(width, height)
    a = 0.5 * (FOCAL_LENGTH_MM / (aspect * SENSOR_WIDTH_MM)) / node_fstop
    s = min(width, height) / ((SENSOR_WIDTH_MM / 2.0) / FOCAL_LENGTH_MM)
    for z in (1.2, 3.0, 20.0, 1e10):
        r = min(0.5 * abs(a * (s * (1.0 / args.focus - 1.0 / z) - 1.0)), args.max_blur)
        thin = 0.5 * (FOCAL_LENGTH_MM / 1000.0 / args.fstop) * abs(1.0 / args.focus - 1.0 / z) * \
            FOCAL_LENGTH_MM * width / SENSOR_WIDTH_MM
        print("blur radius at z = %g m: node %.3f px, Cycles thin lens %.3f px" % (z, r, thin))
    print("image %s: %d x %d; N %.4g -> node f_stop %.4g; focus %.4g m; blur_max %g px; threshold %g px; "
          "threads %s; %s" % (args.image, width, height, args.fstop, node_fstop, args.focus, args.max_blur,
                              args.threshold, args.threads or "all", args.execution_mode), flush=True)

    runs = []
    for _ in range(args.repeat):
        start = time.perf_counter()
        bpy.ops.render.render(write_still=False)
        runs.append(time.perf_counter() - start)
        print("defocus_run_seconds=%.4f" % runs[-1], flush=True)

    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR"
    settings.color_mode = "RGB"
    settings.color_depth = "32"
    settings.exr_codec = "ZIP"
    bpy.data.images["Render Result"].save_render(filepath=os.path.abspath(args.out), scene=scene)
    print("wrote", args.out)
    print("defocus_seconds=%.4f" % min(runs), flush=True)


main()
