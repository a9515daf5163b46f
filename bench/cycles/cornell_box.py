# Blender Cycles (CPU) on the McGuire Cornell box, set up to match lucent's scenes/cornell-box.json:
# the same OBJ, pure Lambertian materials with the MTL's Kd, the light's Ke as one-sided emitted
# radiance, lucent's camera, no denoising, no adaptive sampling, no clamping, a fixed sample
# count. Prints the render time and paths/s (width x height x spp / time) and the mean of the
# linear image. Run headless (scripts/bench-cycles.sh does):
#
#   blender -b -noaudio --factory-startup -P bench/cycles/cornell_box.py -- \
#     --obj OBJ --scene scenes/cornell-box.json --size 256 --spp 256 --threads 2 \
#     --max-depth 8 --output out.exr
#
# Bounces: lucent's max_depth counts path segments (1: emitters seen by the camera, 2: direct
# light, docs/rendering-model.md). Cycles' max_bounces B gives direct light at B = 0 (the kernel
# stores B + 1 and, after the (B+1)-th scattering, lets the ray pick up only emission), so its
# longest path has B + 2 segments: B = max_depth - 2, applied to every bounce type.
import json
import math
import os
import sys
import time

import bmesh
import bpy
from mathutils import Vector


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    opts = {"obj": None, "scene": None, "size": 256, "spp": 256, "threads": 2, "max_depth": 8,
            "output": None, "seed": 0}
    i = 0
    while i < len(argv):
        key = argv[i].lstrip("-").replace("-", "_")
        if key not in opts or i + 1 >= len(argv):
            sys.exit("cornell_box.py: unknown or incomplete option " + argv[i])
        opts[key] = argv[i + 1]
        i += 2
    for k in ("size", "spp", "threads", "max_depth", "seed"):
        opts[k] = int(opts[k])
    if not opts["obj"] or not opts["scene"]:
        sys.exit("cornell_box.py: --obj and --scene are required")
    return opts


def read_mtl(path):
    """Kd and Ke of every material of an MTL file."""
    mats, cur = {}, None
    with open(path) as f:
        for line in f:
            words = line.split("#")[0].split()
            if not words:
                continue
            if words[0] == "newmtl":
                cur = words[1]
                mats[cur] = {"Kd": (0.0, 0.0, 0.0), "Ke": (0.0, 0.0, 0.0)}
            elif cur and words[0] in ("Kd", "Ke") and len(words) >= 4:
                mats[cur][words[0]] = tuple(float(w) for w in words[1:4])
    return mats


def obj_to_blender(p):
    """The importer's default axes (forward -Z, up Y): OBJ (x, y, z) -> Blender (x, -z, y)."""
    return Vector((p[0], -p[2], p[1]))


def lambert_material(mat, kd, ke):
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    diffuse = nt.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (*kd, 1.0)
    diffuse.inputs["Roughness"].default_value = 0.0  # Lambert, not Oren-Nayar
    if max(ke) <= 0:
        nt.links.new(diffuse.outputs["BSDF"], out.inputs["Surface"])
        return
    # lucent's area lights emit from their front side only: mask the back with Backfacing.
    emission = nt.nodes.new("ShaderNodeEmission")
    emission.inputs["Color"].default_value = (*ke, 1.0)
    emission.inputs["Strength"].default_value = 1.0  # emitted radiance = Color x Strength
    add = nt.nodes.new("ShaderNodeAddShader")
    nt.links.new(diffuse.outputs["BSDF"], add.inputs[0])
    nt.links.new(emission.outputs["Emission"], add.inputs[1])
    geometry = nt.nodes.new("ShaderNodeNewGeometry")
    mix = nt.nodes.new("ShaderNodeMixShader")
    nt.links.new(geometry.outputs["Backfacing"], mix.inputs["Fac"])
    nt.links.new(add.outputs["Shader"], mix.inputs[1])
    nt.links.new(diffuse.outputs["BSDF"], mix.inputs[2])
    nt.links.new(mix.outputs["Shader"], out.inputs["Surface"])


def main():
    o = parse_args()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene

    if hasattr(bpy.ops.wm, "obj_import"):
        bpy.ops.wm.obj_import(filepath=o["obj"], forward_axis="NEGATIVE_Z", up_axis="Y")
    else:
        bpy.ops.import_scene.obj(filepath=o["obj"], axis_forward="-Z", axis_up="Y")
    # CornellBox-Original.obj's "bottom" faces of both boxes repeat the vertices of a side face
    # (f -12..-9 and f -8..-5 count back too far): two coplanar twins, where Cycles shows shadow
    # acne (dark stripes on the tall box's front, -3% image mean) and lucent does not. Welding
    # the vertices (which drops faces that become identical) and dropping any remaining exact
    # duplicate leaves 16 of the 18 quads: the geometry lucent effectively renders. Flat shading.
    before = after = 0
    for ob in [ob for ob in bpy.data.objects if ob.type == "MESH"]:
        bm = bmesh.new()
        bm.from_mesh(ob.data)
        before += len(bm.faces)
        bmesh.ops.remove_doubles(bm, verts=bm.verts, dist=1e-6)
        seen, dups = set(), []
        for face in bm.faces:
            key = frozenset(v.index for v in face.verts)
            if key in seen:
                dups.append(face)
            seen.add(key)
        bmesh.ops.delete(bm, geom=dups, context="FACES_ONLY")
        after += len(bm.faces) - len(dups)
        bm.to_mesh(ob.data)
        bm.free()
        for poly in ob.data.polygons:
            poly.use_smooth = False
    print("cycles: %d faces imported, %d after merging duplicates" % (before, after))
    mtl = read_mtl(os.path.splitext(o["obj"])[0] + ".mtl")
    for mat in bpy.data.materials:
        name = mat.name.split(".")[0]
        if name not in mtl:
            sys.exit("cornell_box.py: material %s is not in the MTL" % mat.name)
        lambert_material(mat, mtl[name]["Kd"], mtl[name]["Ke"])

    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world

    with open(o["scene"]) as f:
        cam_json = json.load(f)["camera"]
    cam_data = bpy.data.cameras.new("camera")
    cam_data.sensor_fit = "VERTICAL"
    cam_data.angle_y = math.radians(cam_json["fov"])  # lucent's fov is vertical
    cam = bpy.data.objects.new("camera", cam_data)
    scene.collection.objects.link(cam)
    pos = obj_to_blender(cam_json["position"])
    direction = obj_to_blender(cam_json["look_at"]) - pos
    up = obj_to_blender(cam_json["up"])
    if (up - Vector((0, 0, 1))).length > 1e-6:
        sys.exit("cornell_box.py: only a camera whose up is the OBJ's +Y is supported")
    cam.location = pos
    cam.rotation_mode = "QUATERNION"
    cam.rotation_quaternion = direction.to_track_quat("-Z", "Y")
    scene.camera = cam

    r = scene.render
    r.engine = "CYCLES"
    r.resolution_x = r.resolution_y = o["size"]
    r.resolution_percentage = 100
    r.threads_mode = "FIXED"
    r.threads = o["threads"]
    r.film_transparent = False
    r.use_persistent_data = False
    c = scene.cycles
    c.device = "CPU"
    c.samples = o["spp"]
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.seed = o["seed"]
    bounces = max(0, o["max_depth"] - 2)
    c.max_bounces = c.diffuse_bounces = c.glossy_bounces = bounces
    c.transmission_bounces = c.volume_bounces = c.transparent_max_bounces = bounces
    c.sample_clamp_direct = 0.0  # Blender's default clamps indirect light at 10: a bias
    c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.caustics_reflective = c.caustics_refractive = True
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    scene.display_settings.display_device = "sRGB"

    output = o["output"]
    if output:
        r.image_settings.file_format = "OPEN_EXR"
        r.image_settings.color_depth = "32"
        r.image_settings.exr_codec = "ZIP"
        r.filepath = output
        r.use_file_extension = False

    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=bool(output))
    t1 = time.perf_counter()

    # Cycles' own sampling time (from "Sample 0/N" to "Sample N/N", scene sync and BVH build
    # before it) is in Blender's status lines on stdout: scripts/bench-cycles.sh reads it there.
    n = o["size"] * o["size"] * o["spp"]
    wall = t1 - t0
    print("cycles: blender %s, %dx%d, %d spp, max_bounces %d (lucent max_depth %d), %d threads"
          % (bpy.app.version_string, o["size"], o["size"], o["spp"], bounces, o["max_depth"],
             o["threads"]))
    print("cycles: render call (sync, BVH, sampling, EXR write) %.3f s: %.4f Mpaths/s"
          % (wall, n / wall * 1e-6))
    if output:
        img = bpy.data.images.load(output)
        px = img.pixels[:]
        ch = img.channels
        npx = len(px) // ch
        means = [sum(px[c::ch]) / npx for c in range(3)]
        print("cycles: image mean (linear) R %.5f G %.5f B %.5f, average %.5f"
              % (means[0], means[1], means[2], sum(means) / 3))


main()
