"""Renders a procedural scene with Cycles twice, as an all-in-focus input and a thin-lens reference.

Run:  blender -b --factory-startup -t 2 --python bench/blender/make_reference.py -- \
          --out DIR --width 960 --height 540 --fstop 1.4 --focus 3 --spp 1024

Writes (see bench/blender/README.md):
  DIR/pinhole.exr    depth of field off; channels R, G, B (linear, 32-bit float) and Z (Cycles' depth
                     pass: planar depth along the view axis in metres, 1e10 where the ray escapes to
                     the sky)
  DIR/reference.exr  the same camera with a thin lens: f-number N, focus distance M (planar), round
                     aperture (0 blades); R, G, B only
  DIR/scene.json     camera, render settings, timings and where each part of the scene lies

Camera: at the origin looking along +Y (Blender world), up +Z, so a point's planar depth is its Y
coordinate. 50 mm focal length on a 36 mm wide sensor, sensor fit horizontal. Both renders use the
same seed, sample count, a 1-px box pixel filter, no adaptive sampling, no denoiser, no clamping.
"""
import argparse
import json
import math
import os
import sys
import time

import bpy

FOCAL_LENGTH_MM = 50.0
SENSOR_WIDTH_MM = 36.0

# Planar depths (metres) of the scene's parts; the camera looks along +Y.
WALL_Y = 3.0
WALL_TOP_Z = 0.15
GROUND_Z = -0.45
FAR_Y = 20.0
FAR_TOP_Z = 2.6
OCCLUDER_Y = 1.2
# The portrait scene (--scene portrait).
SUBJECT_Y = 1.0
PORTRAIT_WALL_Y = 5.0
# The table scene (--scene table): a table top receding from the camera's feet to a far wall.
TABLE_Z = -0.25
TABLE_NEAR_Y = 0.35
TABLE_FAR_Y = 4.0
TABLE_WALL_Y = 8.0
# The fence scene (--scene fence): thin bars in front of a lit wall.
FENCE_Y = 1.5
FENCE_WALL_Y = 6.0
# The objects scene (--scene objects): round and tilted subjects at about 1.2 m.
OBJECTS_Y = 1.2
OBJECTS_WALL_Y = 4.0
OBJECTS_LIGHTS_Y = 15.0
OBJECTS_LEAF_Y = 0.6
OBJECTS_FLOOR_Z = -0.2


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="make_reference.py", description=__doc__.splitlines()[0])
    p.add_argument("--out", required=True, help="output directory (created)")
    p.add_argument("--width", type=int, required=True, help="image width, px")
    p.add_argument("--height", type=int, required=True, help="image height, px")
    p.add_argument("--fstop", type=float, required=True, help="f-number N of the thin-lens reference (> 0)")
    p.add_argument("--focus", type=float, required=True, help="focus distance M, metres, planar (> 0)")
    p.add_argument("--spp", type=int, required=True, help="samples per pixel for both renders (>= 1)")
    p.add_argument("--threads", type=int, default=0, help="render threads, 0 = all (also pass blender -t)")
    p.add_argument("--seed", type=int, default=0, help="Cycles seed, the same for both renders")
    p.add_argument("--scene", choices=["street", "portrait", "table", "fence", "objects"], default="street",
                   help="street: posts and a sign at 1.2 m, walls at 3 and 20 m, string lights (default); "
                        "portrait: a sharp striped bar, a checkered disc and a thin rod at 1 m over a "
                        "textured wall at 5 m with highlights (the sharp-subject case); "
                        "table: a checkered table top receding from 0.35 to 4 m (continuous depth) with "
                        "blocks and a post on it at 0.7, 1.5 and 2.5 m, a wall at 8 m, highlights at "
                        "every depth (focus on the 1.5 m block); "
                        "fence: bars 1-3 px wide and a wire mesh at 1.5 m over a brick wall at 6 m with "
                        "highlights, some just behind a bar; "
                        "objects: a checkered sphere, a tilted cube and a leaning card at about 1.2 m "
                        "(depth varying along their silhouettes) on a floor, a tilted leaf at 0.6 m, a "
                        "wall at 4 m and lights at 15 m")
    p.add_argument("--skip-pinhole", action="store_true",
                   help="render only reference.exr (reuse an existing DIR/pinhole.exr)")
    a = p.parse_args(argv)
    for name in ("width", "height", "spp"):
        if getattr(a, name) < 1:
            p.error(f"--{name} = {getattr(a, name)}: must be >= 1")
    if not a.fstop > 0 or not a.focus > 0:
        p.error("--fstop and --focus must be > 0")
    return a


def material(name, build):
    """A node material; build(nodes, links) returns the BSDF/emission output socket."""
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nodes, links = m.node_tree.nodes, m.node_tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    links.new(build(nodes, links), out.inputs["Surface"])
    return m


def diffuse(name, colour_socket_fn):
    def build(nodes, links):
        bsdf = nodes.new("ShaderNodeBsdfDiffuse")
        colour_socket_fn(nodes, links, bsdf.inputs["Color"])
        return bsdf.outputs["BSDF"]
    return material(name, build)


def emission(name, rgb, strength):
    def build(nodes, links):
        e = nodes.new("ShaderNodeEmission")
        e.inputs["Color"].default_value = (*rgb, 1.0)
        e.inputs["Strength"].default_value = strength
        return e.outputs["Emission"]
    return material(name, build)


def brick_colour(nodes, links, target):
    tc = nodes.new("ShaderNodeTexCoord")
    brick = nodes.new("ShaderNodeTexBrick")
    brick.inputs["Scale"].default_value = 4.0          # object coordinates: ~0.23 x 0.08 m bricks
    brick.inputs["Mortar Size"].default_value = 0.015
    brick.inputs["Color1"].default_value = (0.40, 0.12, 0.06, 1)
    brick.inputs["Color2"].default_value = (0.20, 0.17, 0.19, 1)
    brick.inputs["Mortar"].default_value = (0.30, 0.29, 0.27, 1)
    brick.offset_frequency = 2
    brick.squash_frequency = 2
    noise = nodes.new("ShaderNodeTexNoise")
    noise.inputs["Scale"].default_value = 60.0
    noise.inputs["Detail"].default_value = 4.0
    mix = nodes.new("ShaderNodeMixRGB")
    mix.blend_type = "MULTIPLY"
    mix.inputs["Fac"].default_value = 0.5
    # The brick texture is 2-D in (x, y); turn the wall's (x, z) into (x, y).
    mapping = nodes.new("ShaderNodeMapping")
    mapping.inputs["Rotation"].default_value = (math.radians(90.0), 0.0, 0.0)
    links.new(tc.outputs["Object"], mapping.inputs["Vector"])
    links.new(mapping.outputs["Vector"], brick.inputs["Vector"])
    links.new(tc.outputs["Object"], noise.inputs["Vector"])
    links.new(brick.outputs["Color"], mix.inputs["Color1"])
    links.new(noise.outputs["Color"], mix.inputs["Color2"])
    links.new(mix.outputs["Color"], target)


def checker_colour(scale, c1, c2):
    def fn(nodes, links, target):
        tc = nodes.new("ShaderNodeTexCoord")
        ch = nodes.new("ShaderNodeTexChecker")
        ch.inputs["Scale"].default_value = scale
        ch.inputs["Color1"].default_value = (*c1, 1)
        ch.inputs["Color2"].default_value = (*c2, 1)
        links.new(tc.outputs["Object"], ch.inputs["Vector"])
        links.new(ch.outputs["Color"], target)
    return fn


def noise_colour(scale, c1, c2):
    def fn(nodes, links, target):
        tc = nodes.new("ShaderNodeTexCoord")
        n = nodes.new("ShaderNodeTexNoise")
        n.inputs["Scale"].default_value = scale
        n.inputs["Detail"].default_value = 6.0
        ramp = nodes.new("ShaderNodeValToRGB")
        ramp.color_ramp.elements[0].color = (*c1, 1)
        ramp.color_ramp.elements[1].color = (*c2, 1)
        links.new(tc.outputs["Object"], n.inputs["Vector"])
        links.new(n.outputs["Fac"], ramp.inputs["Fac"])
        links.new(ramp.outputs["Color"], target)
    return fn


def stripe_colour(scale, c1, c2):
    """Horizontal stripes with hard edges: a checker that varies along z only."""
    def fn(nodes, links, target):
        tc = nodes.new("ShaderNodeTexCoord")
        mapping = nodes.new("ShaderNodeMapping")
        mapping.inputs["Scale"].default_value = (0.0, 0.0, 1.0)
        ch = nodes.new("ShaderNodeTexChecker")
        ch.inputs["Scale"].default_value = scale
        ch.inputs["Color1"].default_value = (*c1, 1)
        ch.inputs["Color2"].default_value = (*c2, 1)
        links.new(tc.outputs["Object"], mapping.inputs["Vector"])
        links.new(mapping.outputs["Vector"], ch.inputs["Vector"])
        links.new(ch.outputs["Color"], target)
    return fn


def flat_colour(rgb):
    def fn(nodes, links, target):
        target.default_value = (*rgb, 1)
    return fn


def box(name, x0, x1, y0, y1, z0, z1, mat):
    """An axis-aligned box from corner to corner (metres)."""
    import bmesh
    mesh = bpy.data.meshes.new(name)
    bm = bmesh.new()
    bmesh.ops.create_cube(bm, size=1.0)
    for v in bm.verts:
        v.co.x = x0 if v.co.x < 0 else x1
        v.co.y = y0 if v.co.y < 0 else y1
        v.co.z = z0 if v.co.z < 0 else z1
    bm.to_mesh(mesh)
    bm.free()
    ob = bpy.data.objects.new(name, mesh)
    ob.data.materials.append(mat)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def quad(name, corners, mat):
    """A flat quad through four corners, in order."""
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(corners, [], [(0, 1, 2, 3)])
    ob = bpy.data.objects.new(name, mesh)
    ob.data.materials.append(mat)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def quad_xz(name, y, x0, x1, z0, z1, mat):
    """A plane facing the camera (normal -Y) at planar depth y."""
    return quad(name, [(x0, y, z0), (x0, y, z1), (x1, y, z1), (x1, y, z0)], mat)


def quad_xy(name, z, x0, x1, y0, y1, mat):
    """A horizontal plane at height z."""
    return quad(name, [(x0, y0, z), (x1, y0, z), (x1, y1, z), (x0, y1, z)], mat)


def sphere(name, centre, radius, mat):
    bpy.ops.mesh.primitive_uv_sphere_add(segments=24, ring_count=12, radius=radius, location=centre)
    ob = bpy.context.active_object
    ob.name = name
    ob.data.materials.append(mat)
    bpy.ops.object.shade_smooth()
    # Seen by the camera only: a highlight in the picture, not a lamp that lights the walls (whose
    # glow would be slow to converge and is not what an all-in-focus input's highlights are).
    ob.visible_diffuse = False
    ob.visible_glossy = False
    ob.visible_transmission = False
    ob.visible_volume_scatter = False
    ob.visible_shadow = False
    return ob


def sky_and_sun(name, sky_rgb, sun_energy, sun_angle_deg, sun_rgb, tilt_deg, turn_deg):
    """A constant world colour (no texture), which also lights the scene softly, and a sun lamp
    rotated tilt_deg about x, then turn_deg about z."""
    scene = bpy.context.scene
    world = bpy.data.worlds.new(name)
    world.use_nodes = True
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (*sky_rgb, 1)
    bg.inputs["Strength"].default_value = 1.0
    scene.world = world
    sun_data = bpy.data.lights.new("sun", type="SUN")
    sun_data.energy = sun_energy
    sun_data.angle = math.radians(sun_angle_deg)
    sun_data.color = sun_rgb
    sun = bpy.data.objects.new("sun", sun_data)
    sun.rotation_euler = (math.radians(tilt_deg), 0.0, math.radians(turn_deg))
    scene.collection.objects.link(sun)


def build_scene(args):
    """Builds the chosen scene and the camera; returns (camera, highlights, planar depths)."""
    scene = bpy.context.scene
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    lights, depths = {"portrait": build_portrait, "table": build_table, "fence": build_fence,
                      "street": build_street, "objects": build_objects}[args.scene](args)
    for name, centre, radius, rgb, strength in lights:
        sphere(name, centre, radius, emission("em_" + name, rgb, strength))

    cam_data = bpy.data.cameras.new("camera")
    cam_data.lens = FOCAL_LENGTH_MM
    cam_data.sensor_width = SENSOR_WIDTH_MM
    cam_data.sensor_fit = "HORIZONTAL"
    cam_data.clip_start = 0.05
    cam_data.clip_end = 1000.0
    cam = bpy.data.objects.new("camera", cam_data)
    cam.location = (0.0, 0.0, 0.0)
    cam.rotation_euler = (math.radians(90.0), 0.0, 0.0)  # look along +Y, up +Z
    scene.collection.objects.link(cam)
    scene.camera = cam
    return cam, lights, depths


def build_portrait(args):
    """The sharp-subject case: patterned foreground at 1 m, in focus, over a textured wall at 5 m.

    Every subject face is a quad at planar depth exactly SUBJECT_Y facing the camera, so its depth is
    one value and it is in focus when --focus is SUBJECT_Y. Its patterns have hard edges in every
    direction (horizontal stripes, a checker, a diagonal rod) and colours the wall does not have.
    """
    sky_and_sun("overcast", (0.35, 0.38, 0.42), 2.0, 3.0, (1.0, 0.9, 0.8), 50.0, -30.0)

    # The wall fills the frame at 5 m (half-width 1.8 m, half-height 1.2 m at 600 x 400).
    wall = diffuse("bricks", brick_colour)
    quad_xz("wall_5m", PORTRAIT_WALL_Y, -4.0, 4.0, -3.0, 3.0, wall)
    # A striped bar (2 cm horizontal stripes, cream and dark blue), full height.
    stripes = diffuse("stripes", stripe_colour(50.0, (0.75, 0.72, 0.6), (0.03, 0.05, 0.2)))
    quad_xz("bar", SUBJECT_Y, -0.16, -0.06, -1.0, 1.0, stripes)
    # A checkered disc (a head) on a neck, and a thin diagonal rod.
    checks = diffuse("checks", checker_colour(40.0, (0.8, 0.15, 0.5), (0.05, 0.3, 0.1)))
    bpy.ops.mesh.primitive_circle_add(vertices=128, radius=0.075, fill_type="NGON",
                                      location=(0.1, SUBJECT_Y, 0.05), rotation=(math.radians(90.0), 0.0, 0.0))
    head = bpy.context.active_object
    head.name = "head"
    head.data.materials.append(checks)
    neck = diffuse("neck", flat_colour((0.6, 0.35, 0.2)))
    quad_xz("neck", SUBJECT_Y + 0.002, 0.08, 0.12, -1.0, -0.02, neck)  # 2 mm behind the head: no z-fighting
    rod = diffuse("rod", flat_colour((0.9, 0.8, 0.1)))
    quad("rod", [(0.2, SUBJECT_Y, -0.3), (0.204, SUBJECT_Y, -0.3), (0.334, SUBJECT_Y, 0.2), (0.33, SUBJECT_Y, 0.2)], rod)
    # Highlights on the wall, some just behind the subject's edges, and one on the subject.
    # wall_a lies 8 px left of the bar's silhouette, wall_b behind the bar, wall_c behind the head.
    lights = [("wall_a", (-0.84, PORTRAIT_WALL_Y - 0.02, 0.3), 0.012, (1.0, 0.9, 0.7), 100.0),
              ("wall_b", (-0.5, PORTRAIT_WALL_Y - 0.02, -0.2), 0.012, (0.3, 0.5, 1.0), 150.0),
              ("wall_c", (0.75, PORTRAIT_WALL_Y - 0.02, 0.1), 0.012, (1.0, 0.3, 0.2), 150.0),
              ("wall_d", (1.2, PORTRAIT_WALL_Y - 0.02, -0.6), 0.012, (1.0, 1.0, 0.9), 80.0),
              ("wall_e", (-1.3, PORTRAIT_WALL_Y - 0.02, -0.7), 0.012, (0.4, 1.0, 0.5), 120.0),
              ("subject_glint", (0.09, SUBJECT_Y - 0.002, 0.08), 0.0014, (1.0, 1.0, 1.0), 60.0)]
    depths = {"subject_faces": SUBJECT_Y, "wall": PORTRAIT_WALL_Y}
    return lights, depths


def build_table(args):
    """Continuous depth: a table top from the camera's feet into the distance, things on it at three
    depths (one in focus at 1.5 m), a far wall, and highlights near, in focus and far.

    The table top is one plane, so its depth runs through every layer the scatter makes; its checker
    has hard edges whose blur grows steadily with distance from the focus. The blocks' front faces
    face the camera at one planar depth each, with hard-edged patterns.
    """
    sky_and_sun("evening", (0.2, 0.22, 0.3), 3.0, 3.0, (1.0, 0.85, 0.7), 55.0, 25.0)

    top = diffuse("table_top", checker_colour(12.0, (0.55, 0.45, 0.3), (0.15, 0.1, 0.07)))
    quad_xy("table_top", TABLE_Z, -2.5, 2.5, TABLE_NEAR_Y, TABLE_FAR_Y, top)
    wall = diffuse("far_wall", noise_colour(3.0, (0.05, 0.06, 0.09), (0.35, 0.3, 0.25)))
    quad_xz("wall_8m", TABLE_WALL_Y, -6.0, 6.0, -3.0, 3.0, wall)
    # A striped block near the camera (blurred foreground), a checkered one in focus, a post behind.
    near = diffuse("near_block", stripe_colour(60.0, (0.9, 0.85, 0.7), (0.1, 0.25, 0.5)))
    box("near_block", 0.12, 0.26, 0.7, 0.78, TABLE_Z, TABLE_Z + 0.12, near)
    mid = diffuse("mid_block", checker_colour(50.0, (0.85, 0.2, 0.15), (0.9, 0.9, 0.85)))
    box("mid_block", -0.28, -0.08, 1.5, 1.6, TABLE_Z, TABLE_Z + 0.2, mid)
    post = diffuse("far_post", flat_colour((0.15, 0.45, 0.2)))
    box("far_post", 0.35, 0.45, 2.5, 2.6, TABLE_Z, 0.6, post)
    # Highlights: a row of small lights along the table's left side at every depth, one on the
    # in-focus block's face, two on the far wall.
    lights = []
    for i, y in enumerate([0.6, 0.9, 1.3, 1.8, 2.4, 3.2]):
        lights.append(("table_%d" % i, (-0.45 - 0.05 * y, y, TABLE_Z + 0.01), 0.0025 * y, (1.0, 0.75, 0.4), 100.0))
    lights += [("block_glint", (-0.18, 1.5 - 0.002, TABLE_Z + 0.1), 0.0015, (1.0, 1.0, 1.0), 80.0),
               ("wall_a", (1.1, TABLE_WALL_Y - 0.02, 0.4), 0.012, (0.3, 0.5, 1.0), 150.0),
               ("wall_b", (-0.9, TABLE_WALL_Y - 0.02, 0.7), 0.012, (1.0, 0.3, 0.2), 150.0)]
    depths = {"table_top": "z = %.2f m, from %.2f to %.1f m" % (TABLE_Z, TABLE_NEAR_Y, TABLE_FAR_Y),
              "near_block_front_face": 0.7, "mid_block_front_face": 1.5, "far_post_front_face": 2.5,
              "wall": TABLE_WALL_Y}
    return lights, depths


def build_fence(args):
    """Thin foreground structure: vertical bars of 1 to 3 px and a diagonal wire mesh at 1.5 m over a
    brick wall at 6 m, with highlights on the wall, some half behind a bar.

    Sub-pixel and few-pixel features are where edge pixels are all edge (no pure pixel of the near
    surface beside them) and where a blurred foreground lets most of the background through.
    """
    sky_and_sun("day", (0.45, 0.5, 0.6), 3.0, 3.0, (1.0, 0.95, 0.85), 50.0, -35.0)
    wall = diffuse("bricks", brick_colour)
    quad_xz("wall_6m", FENCE_WALL_Y, -5.0, 5.0, -3.5, 3.5, wall)
    metal = diffuse("metal", flat_colour((0.08, 0.08, 0.09)))
    paint = diffuse("paint", flat_colour((0.75, 0.7, 0.2)))
    # Vertical bars, 2.5 mm to 7.5 mm wide (about 1.4 to 4.2 px at 600 px), 8 cm apart.
    px_m = FENCE_Y * SENSOR_WIDTH_MM / FOCAL_LENGTH_MM / args.width  # metres per pixel at the fence
    for i in range(-7, 8):
        x = 0.08 * i + 0.013
        width_m = px_m * (1.0 + 0.75 * (i % 4)) + 0.0002
        box("bar_%d" % i, x, x + width_m, FENCE_Y, FENCE_Y + 0.01, -1.2, 1.2, paint if i % 3 == 0 else metal)
    # A wire mesh along the bottom of the frame: thin diagonal wires (about 1 px) both ways.
    for i in range(-12, 13):
        x = 0.06 * i
        for sgn in (1.0, -1.0):
            y = FENCE_Y - 0.002
            quad("wire_%d_%d" % (i, int(sgn)),
                 [(x, y, -0.36), (x + px_m, y, -0.36), (x + px_m + sgn * 0.24, y, -0.12), (x + sgn * 0.24, y, -0.12)], metal)
    lights = []
    colours = [(1.0, 0.8, 0.5), (0.4, 0.6, 1.0), (1.0, 0.3, 0.2), (0.5, 1.0, 0.4)]
    for i in range(10):
        # Every other one lies right behind a bar's edge (as the camera sees it).
        bar_x = 0.08 * (i - 5) + 0.013
        x = bar_x * FENCE_WALL_Y / FENCE_Y + (0.0 if i % 2 == 0 else 0.09)
        z = 0.35 + 0.12 * (i % 3)
        lights.append(("wall_%d" % i, (x, FENCE_WALL_Y - 0.03, z), 0.014, colours[i % 4], 120.0))
    depths = {"bars_and_wires": FENCE_Y, "wall": FENCE_WALL_Y}
    return lights, depths


def build_objects(args):
    """Subjects that do not face the camera: a checkered sphere (its depth grows to the silhouette,
    where the surface turns away), a cube turned on two axes and a card leaning back through the focus
    (depth varying along their edges), standing on a floor that recedes through every layer; a leaf
    tilted in depth in front of them (a blurred foreground whose own blur varies), a noise-textured
    wall at 4 m and lights at 15 m, some just beside a subject's silhouette.
    """
    sky_and_sun("afternoon", (0.3, 0.33, 0.4), 3.0, 3.0, (1.0, 0.9, 0.75), 45.0, -25.0)
    wall = diffuse("plaster", noise_colour(6.0, (0.12, 0.1, 0.09), (0.55, 0.5, 0.42)))
    quad_xz("wall_4m", OBJECTS_WALL_Y, -3.0, 3.0, OBJECTS_FLOOR_Z, 0.25, wall)
    far = diffuse("far", noise_colour(1.5, (0.03, 0.04, 0.06), (0.15, 0.13, 0.1)))
    quad_xz("far_15m", OBJECTS_LIGHTS_Y + 0.5, -12.0, 12.0, OBJECTS_FLOOR_Z, 4.0, far)
    floor = diffuse("floor", checker_colour(10.0, (0.4, 0.38, 0.33), (0.12, 0.11, 0.1)))
    quad_xy("floor", OBJECTS_FLOOR_Z, -2.5, 2.5, 0.3, OBJECTS_WALL_Y, floor)
    # The sphere: 10 cm radius (about 64 px at 600 px), finely tessellated so that its silhouette is
    # round, resting on the floor with its front at the focus.
    ball = diffuse("ball", checker_colour(25.0, (0.85, 0.12, 0.1), (0.9, 0.88, 0.8)))
    bpy.ops.mesh.primitive_uv_sphere_add(segments=96, ring_count=48, radius=0.1,
                                         location=(-0.12, OBJECTS_Y + 0.1, OBJECTS_FLOOR_Z + 0.1))
    sphere_ob = bpy.context.active_object
    sphere_ob.name = "ball"
    sphere_ob.data.materials.append(ball)
    bpy.ops.object.shade_smooth()
    # The cube: 12 cm, turned 35 deg about the vertical and 20 deg about the horizontal.
    cube_mat = diffuse("cube", stripe_colour(60.0, (0.1, 0.3, 0.75), (0.85, 0.8, 0.5)))
    bpy.ops.mesh.primitive_cube_add(size=0.12, location=(0.16, OBJECTS_Y + 0.06, OBJECTS_FLOOR_Z + 0.085),
                                    rotation=(math.radians(20.0), 0.0, math.radians(35.0)))
    cube_ob = bpy.context.active_object
    cube_ob.name = "cube"
    cube_ob.data.materials.append(cube_mat)
    # A card leaning back 40 deg from upright, its foot at the focus: depth 1.2 m at its foot to 1.35 m at its top.
    card = diffuse("card", checker_colour(45.0, (0.1, 0.45, 0.15), (0.85, 0.85, 0.8)))
    quad("card", [(0.26, OBJECTS_Y, OBJECTS_FLOOR_Z), (0.36, OBJECTS_Y, OBJECTS_FLOOR_Z),
                  (0.36, OBJECTS_Y + 0.15, OBJECTS_FLOOR_Z + 0.18), (0.26, OBJECTS_Y + 0.15, OBJECTS_FLOOR_Z + 0.18)], card)
    # The leaf: a plane tilted from 0.55 to 0.7 m in the lower left of the frame (a blurred foreground
    # whose blur varies across it).
    leaf = diffuse("leaf", noise_colour(30.0, (0.05, 0.2, 0.03), (0.25, 0.5, 0.1)))
    quad("leaf", [(-0.2, OBJECTS_LEAF_Y - 0.05, -0.14), (-0.1, OBJECTS_LEAF_Y - 0.05, -0.13),
                  (-0.09, OBJECTS_LEAF_Y + 0.1, -0.06), (-0.2, OBJECTS_LEAF_Y + 0.1, -0.07)], leaf)
    lights = []
    colours = [(1.0, 0.75, 0.4), (0.3, 0.5, 1.0), (1.0, 0.25, 0.2), (0.4, 1.0, 0.45)]
    for i in range(9):
        x = -5.0 + 1.25 * i
        z = 1.2 + 0.3 * math.sin(i)
        lights.append(("far_%d" % i, (x, OBJECTS_LIGHTS_Y, z), 0.025, colours[i % 4], 120.0))
    # Wall lights: one about 10 px beside the sphere's silhouette as the camera sees it, one beside the cube.
    wall_y = OBJECTS_WALL_Y - 0.02
    lights += [("wall_ball", (-0.611, wall_y, -0.072), 0.008, (1.0, 0.95, 0.8), 120.0),
               ("wall_cube", (0.85, wall_y, -0.15), 0.008, (0.3, 0.6, 1.0), 150.0),
               ("wall_free", (-1.2, wall_y, 0.1), 0.008, (1.0, 0.4, 0.3), 100.0),
               ("ball_glint", (-0.14, OBJECTS_Y + 0.003, OBJECTS_FLOOR_Z + 0.12), 0.0014, (1.0, 1.0, 1.0), 60.0)]
    depths = {"ball_front_m": OBJECTS_Y, "ball_silhouette_m": OBJECTS_Y + 0.1, "cube_centre_m": OBJECTS_Y + 0.06,
              "card_m": "%.2f to %.2f" % (OBJECTS_Y, OBJECTS_Y + 0.15), "leaf_m": "0.55 to 0.70",
              "wall": OBJECTS_WALL_Y, "lights": OBJECTS_LIGHTS_Y, "far_plane": OBJECTS_LIGHTS_Y + 0.5,
              "floor": "z = %.2f m, from 0.3 to %.1f m" % (OBJECTS_FLOOR_Z, OBJECTS_WALL_Y)}
    return lights, depths


def build_street(args):
    """Posts and a round sign at 1.2 m, a brick wall at 3 m over a checker ground, a far wall at 20 m."""
    # Dusk sky, and a low sun from behind the camera, up and to the left (light travels +x, +y, -z):
    # the post casts a shadow on the wall.
    sky_and_sun("dusk", (0.06, 0.09, 0.22), 2.5, 2.0, (1.0, 0.85, 0.7), 60.0, -20.0)

    wall = diffuse("bricks", brick_colour)
    quad_xz("wall_3m", WALL_Y, -2.0, 2.0, GROUND_Z, WALL_TOP_Z, wall)
    ground = diffuse("ground", checker_colour(8.0, (0.25, 0.24, 0.2), (0.08, 0.08, 0.07)))
    quad_xy("ground", GROUND_Z, -3.0, 3.0, 0.3, WALL_Y, ground)
    far = diffuse("far", noise_colour(1.5, (0.02, 0.03, 0.05), (0.12, 0.10, 0.08)))
    quad_xz("far_20m", FAR_Y, -15.0, 15.0, GROUND_Z, FAR_TOP_Z, far)

    # Foreground occluders at 1.2 m: a dark square post (front face at y = 1.2) and a round sign.
    post = diffuse("post", noise_colour(40.0, (0.02, 0.015, 0.01), (0.06, 0.045, 0.03)))
    box("post", -0.30, -0.22, OCCLUDER_Y, OCCLUDER_Y + 0.08, GROUND_Z, 1.5, post)
    sign = diffuse("sign", flat_colour((0.5, 0.05, 0.03)))
    bpy.ops.mesh.primitive_cylinder_add(vertices=128, radius=0.1, depth=0.01,
                                        location=(0.3, OCCLUDER_Y + 0.005, -0.12),
                                        rotation=(math.radians(90.0), 0.0, 0.0))
    disc = bpy.context.active_object
    disc.name = "sign_disc"
    disc.data.materials.append(sign)
    box("sign_pole", 0.29, 0.31, OCCLUDER_Y + 0.01, OCCLUDER_Y + 0.03, GROUND_Z, -0.2, post)

    # Emissive spheres (radiance = strength x colour), ~2 px radius at 960 px width wherever they are.
    lights = []
    colours = [(1.0, 0.7, 0.35), (1.0, 0.15, 0.1), (0.2, 1.0, 0.25), (0.2, 0.35, 1.0), (1.0, 0.8, 0.3)]
    for i in range(11):
        x = -5.0 + i
        z = 1.55 + 0.35 * (x / 5.0) ** 2
        lights.append(("string_%d" % i, (x, FAR_Y - 0.2, z), 0.03, colours[i % 5], 120.0))
    lights += [("wall_a", (0.25, WALL_Y - 0.01, -0.05), 0.004, (1.0, 1.0, 0.95), 100.0),
               ("wall_b", (-0.12, WALL_Y - 0.01, 0.02), 0.004, (1.0, 0.2, 0.15), 150.0),
               ("wall_c", (0.80, WALL_Y - 0.01, 0.05), 0.004, (0.25, 0.5, 1.0), 150.0),
               ("wall_d", (-0.50, WALL_Y - 0.01, -0.30), 0.004, (1.0, 0.75, 0.4), 80.0),
               ("post_bolt", (-0.26, OCCLUDER_Y - 0.002, 0.05), 0.0017, (1.0, 0.95, 0.9), 100.0),
               ("post_led", (-0.26, OCCLUDER_Y - 0.002, -0.20), 0.0017, (0.1, 1.0, 0.9), 120.0),
               ("sign_glint", (0.26, OCCLUDER_Y - 0.002, -0.08), 0.0017, (1.0, 1.0, 1.0), 60.0)]
    depths = {"occluders_front_face": OCCLUDER_Y, "wall": WALL_Y, "far_plane": FAR_Y, "sky": "1e10 (escaped rays)",
              "ground": "z = %.2f m, visible up to %.1f m" % (GROUND_Z, WALL_Y),
              "wall_top_z_m": WALL_TOP_Z, "far_top_z_m": FAR_TOP_Z}
    return lights, depths


def configure_render(args):
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = args.spp
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.use_denoising = False
    scene.cycles.seed = args.seed
    scene.cycles.use_animated_seed = False
    scene.cycles.pixel_filter_type = "BOX"
    scene.cycles.filter_width = 1.0
    scene.cycles.sample_clamp_direct = 0.0
    scene.cycles.sample_clamp_indirect = 0.0
    scene.cycles.max_bounces = 4
    scene.cycles.diffuse_bounces = 3
    scene.cycles.glossy_bounces = 0
    scene.cycles.transmission_bounces = 0
    scene.cycles.transparent_max_bounces = 0
    scene.cycles.caustics_reflective = False
    scene.cycles.caustics_refractive = False
    scene.render.resolution_x = args.width
    scene.render.resolution_y = args.height
    scene.render.resolution_percentage = 100
    scene.render.pixel_aspect_x = scene.render.pixel_aspect_y = 1.0
    scene.render.film_transparent = False
    scene.render.use_compositing = False
    scene.render.use_sequencer = False
    if args.threads > 0:
        scene.render.threads_mode = "FIXED"
        scene.render.threads = args.threads
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    bpy.context.view_layer.use_pass_z = True
    s = scene.render.image_settings
    s.file_format = "OPEN_EXR"
    s.color_mode = "RGB"
    s.color_depth = "32"
    s.exr_codec = "ZIP"


def render_to(path, with_z):
    scene = bpy.context.scene
    scene.render.image_settings.use_zbuffer = with_z
    scene.render.filepath = path
    start = time.perf_counter()
    bpy.ops.render.render(write_still=False)
    seconds = time.perf_counter() - start
    bpy.data.images["Render Result"].save_render(filepath=path, scene=scene)
    print("rendered %s in %.1f s" % (path, seconds), flush=True)
    return seconds


def main():
    args = parse_args()
    os.makedirs(args.out, exist_ok=True)
    cam, lights, depths = build_scene(args)
    configure_render(args)
    scene = bpy.context.scene
    focal_px = args.width * FOCAL_LENGTH_MM / SENSOR_WIDTH_MM

    def pixel_of(p):
        x, y, z = p
        return [args.width / 2 + x / y * focal_px, args.height / 2 - z / y * focal_px]

    times = {}
    if not args.skip_pinhole:
        cam.data.dof.use_dof = False
        times["pinhole_seconds"] = render_to(os.path.join(args.out, "pinhole.exr"), True)
    cam.data.dof.use_dof = True
    cam.data.dof.aperture_fstop = args.fstop
    cam.data.dof.focus_distance = args.focus
    cam.data.dof.aperture_blades = 0
    cam.data.dof.aperture_rotation = 0.0
    cam.data.dof.aperture_ratio = 1.0
    times["reference_seconds"] = render_to(os.path.join(args.out, "reference.exr"), False)

    info = {
        "generator": "bench/blender/make_reference.py",
        "blender_version": bpy.app.version_string,
        "width_px": args.width,
        "height_px": args.height,
        "camera": {
            "model": "Cycles perspective camera; thin lens for reference.exr",
            "focal_length_mm": FOCAL_LENGTH_MM,
            "sensor_width_mm": SENSOR_WIDTH_MM,
            "sensor_fit": "HORIZONTAL",
            "focal_length_px": focal_px,
            "horizontal_fov_deg": math.degrees(2 * math.atan(SENSOR_WIDTH_MM / 2 / FOCAL_LENGTH_MM)),
            "f_number": args.fstop,
            "aperture_radius_m": FOCAL_LENGTH_MM / 1000.0 / (2 * args.fstop),
            "focus_distance_m": args.focus,
            "focus_is_planar": True,
            "aperture_blades": 0,
            "position_m": [0, 0, 0],
            "looks_along": "+Y (planar depth = world Y), up +Z",
        },
        "render": {
            "engine": "CYCLES", "device": "CPU", "spp": args.spp, "seed": args.seed,
            "adaptive_sampling": False, "denoiser": "off", "clamping": "off",
            "pixel_filter": "BOX", "filter_width_px": 1.0,
            "max_bounces": 4, "diffuse_bounces": 3,
            "threads": scene.render.threads if args.threads > 0 else "auto",
        },
        "files": {
            "pinhole.exr": "DoF off; R, G, B linear float32 + Z (Cycles depth pass, planar metres; 1e10 = sky)",
            "reference.exr": "thin lens, same samples and seed; R, G, B linear float32",
        },
        "depth_pass": "planar distance along the view axis (see README for the check)",
        "scene": args.scene,
        "scene_depths_m": depths,
        "highlights": [
            {"name": n, "centre_m": list(c), "radius_m": r, "planar_depth_of_front_m": c[1] - r,
             "radiance_rgb": [s * v for v in rgb], "pixel_xy": pixel_of(c)}
            for n, c, r, rgb, s in lights],
        "timings_s": times,
    }
    with open(os.path.join(args.out, "scene.json"), "w") as f:
        json.dump(info, f, indent=2)
    print("wrote", os.path.join(args.out, "scene.json"), flush=True)


main()
