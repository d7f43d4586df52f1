# A hidden-object reference for the object masks (README: Object masks),
# rendered with Blender's Cycles (Debian's blender, 3.4):
#
#   blender -b --factory-startup --python tools/blender_masks.py -- \
#       SCENE.json OUT_PREFIX HIDE [--res W H] [--samples N] [--furniture FILE.sh3f]
#
# SCENE.json is a scene description of ../shared/data/blender (room.json:
# objects with mesh paths inside Debian sweethome3d-furniture's
# BlendSwap-CC-0.sh3f, a zip, unpacked here into a temporary folder; the
# optional room walls; camera; ao_distance).  HIDE is the label of one of its
# objects: the mesh file's name without extension (e.g. "table").
#
# Writes, with the same camera:
#   OUT_PREFIX.exr          (a) every object: multilayer EXR, 32-bit float,
#                           ZIP: ViewLayer.Depth.Z, Normal.X/Y/Z (world),
#                           DiffCol.R/G/B, AO.R/G/B (Cycles' AO pass at the
#                           scene's ao_distance), IndexOB.X and a Cryptomatte
#                           object layer (ViewLayer.CryptoObject00..02, the
#                           manifest in the header);
#   OUT_PREFIX.camera.json  the camera, laid out as ../shared/data/blender's;
#   OUT_PREFIX_hidden.exr   (b) the same frame with HIDE hidden from
#                           rendering (hide_render): its AO pass is the
#                           reference for --occluders '!HIDE';
#   OUT_PREFIX_ref.exr      the reference as the referee reads it
#                           (../shared/tools/aometrics.py, obscura compare
#                           --mask auto): ViewLayer.AO.R of (b) and
#                           ViewLayer.Depth.Z of (b) set to 1e10 (no
#                           geometry) on the pixels where (a) shows HIDE, so
#                           the metrics cover the surfaces both frames show.
#
# Each object of SCENE.json is joined into one Blender object named by its
# label, with pass_index (IndexOB) 1, 2, ... in the file's order; the ground
# plane is "floor" and the walls "wall_back" and "wall_left" (the next
# indices).  Render settings as ../shared/tools/blender_scene.py (which this
# follows: the placement of meshes, the camera, the world and the channel
# conventions are taken from it): Cycles on the CPU, no denoising, pixel
# filter width 0.01 (one ray through each pixel centre: depth, normals and
# IDs are not blended across edges, Cryptomatte coverage is 1 at rank 0),
# white world, AO distance = the scene's ao_distance.
import numpy
if "bool" not in numpy.__dict__: numpy.bool = bool
import bpy, sys, json, math, mathutils, os, time, zipfile, tempfile, argparse, shutil

argv = sys.argv[sys.argv.index("--") + 1:]
ap = argparse.ArgumentParser(prog="blender_masks.py")
ap.add_argument("scene"); ap.add_argument("out"); ap.add_argument("hide")
ap.add_argument("--res", type=int, nargs=2, default=[320, 240])
ap.add_argument("--samples", type=int, default=256)
ap.add_argument("--furniture", default="/usr/share/sweethome3d/furniture/BlendSwap-CC-0.sh3f")
a = ap.parse_args(argv)
spec = json.load(open(a.scene))
tmp = tempfile.mkdtemp(prefix="blender_masks.")
zipfile.ZipFile(a.furniture).extractall(tmp)

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
labels = []

def place(path, size, pos, rot_z, label, index):
    # as blender_scene.py's place(), then the new meshes joined into one object
    before = set(scene.objects)
    p = os.path.join(tmp, path)
    assert p.endswith(".obj"), "only OBJ meshes: " + path
    bpy.ops.wm.obj_import(filepath=p)
    objs = [o for o in scene.objects if o not in before and o.type == "MESH"]
    bpy.context.view_layer.update()
    pts = [o.matrix_world @ mathutils.Vector(c) for o in objs for c in o.bound_box]
    mn = mathutils.Vector([min(q[i] for q in pts) for i in range(3)])
    mx = mathutils.Vector([max(q[i] for q in pts) for i in range(3)])
    s = size / max(mx - mn)
    centre = mathutils.Vector(((mn.x + mx.x) / 2, (mn.y + mx.y) / 2, mn.z))
    m = (mathutils.Matrix.Translation(mathutils.Vector(pos)) @ mathutils.Matrix.Rotation(math.radians(rot_z), 4, "Z")
         @ mathutils.Matrix.Scale(s, 4) @ mathutils.Matrix.Translation(-centre))
    for o in objs:
        o.matrix_world = m @ o.matrix_world
        for poly in o.data.polygons: poly.use_smooth = True
    bpy.ops.object.select_all(action="DESELECT")
    for o in objs: o.select_set(True)
    bpy.context.view_layer.objects.active = objs[0]
    if len(objs) > 1: bpy.ops.object.join()
    ob = bpy.context.view_layer.objects.active
    ob.name = label; ob.pass_index = index
    labels.append(label)
    return ob

for i, o in enumerate(spec["objects"]):
    label = os.path.splitext(os.path.basename(o["mesh"]))[0]
    place(o["mesh"], o["size"], o.get("pos", [0, 0, 0]), o.get("rot_z", 0), label, i + 1)
n = len(spec["objects"])
bpy.ops.mesh.primitive_plane_add(size=40, location=(0, 0, 0))
bpy.context.object.name = "floor"; bpy.context.object.pass_index = n + 1; labels.append("floor")
if spec.get("room"):
    bpy.ops.mesh.primitive_cube_add(size=1, location=(0, 3.05, 1.5)); bpy.context.object.scale = (8, 0.1, 3)
    bpy.context.object.name = "wall_back"; bpy.context.object.pass_index = n + 2; labels.append("wall_back")
    bpy.ops.mesh.primitive_cube_add(size=1, location=(-3.05, 0, 1.5)); bpy.context.object.scale = (0.1, 8, 3)
    bpy.context.object.name = "wall_left"; bpy.context.object.pass_index = n + 3; labels.append("wall_left")
if a.hide not in labels:
    sys.exit("blender_masks.py: no object '%s' in %s (objects: %s)" % (a.hide, a.scene, ", ".join(labels)))
hidden = bpy.data.objects[a.hide]
print("OBJECTS " + ", ".join("%s=%d" % (l, bpy.data.objects[l].pass_index) for l in labels))

cam_spec = spec["camera"]
cd = bpy.data.cameras.new("Cam"); cam = bpy.data.objects.new("Cam", cd); scene.collection.objects.link(cam)
cam.location = cam_spec["pos"]
d = mathutils.Vector(cam_spec["target"]) - cam.location
cam.rotation_euler = d.to_track_quat("-Z", "Y").to_euler(); scene.camera = cam
cd.sensor_fit = "VERTICAL"; cd.angle_y = math.radians(cam_spec["fov_y"])
cd.clip_start = 0.05; cd.clip_end = 100

w, h = a.res
world = bpy.data.worlds.new("W"); scene.world = world; world.use_nodes = True
world.node_tree.nodes["Background"].inputs[0].default_value = (1, 1, 1, 1)
world.light_settings.distance = spec["ao_distance"]
scene.render.resolution_x = w; scene.render.resolution_y = h; scene.render.resolution_percentage = 100
scene.render.engine = "CYCLES"; scene.cycles.device = "CPU"
scene.cycles.samples = a.samples; scene.cycles.use_denoising = False
scene.cycles.pixel_filter_width = 0.01
# The AO pass is taken at the camera ray's first hit (Cycles' integrate_surface_ao_pass,
# PATH_RAY_CAMERA only) and does not depend on later bounces; none are traced.
scene.cycles.max_bounces = 0
vl = scene.view_layers[0]
vl.use_pass_z = True; vl.use_pass_normal = True; vl.use_pass_ambient_occlusion = True
vl.use_pass_diffuse_color = True; vl.use_pass_object_index = True
vl.use_pass_combined = False   # the beauty is not needed (and without bounces not a beauty)
vl.use_pass_cryptomatte_object = True; vl.pass_cryptomatte_depth = 6
st = scene.render.image_settings
st.file_format = "OPEN_EXR_MULTILAYER"; st.color_depth = "32"; st.exr_codec = "ZIP"

def render(path):
    scene.render.filepath = path
    t = time.time(); bpy.ops.render.render(write_still=True)
    print("RENDER_SECONDS %s %.2f" % (os.path.basename(path), time.time() - t))

render(a.out + ".exr")
hidden.hide_render = True
render(a.out + "_hidden.exr")
hidden.hide_render = False
shutil.rmtree(tmp, ignore_errors=True)

w2c = cam.matrix_world.inverted()
proj = cam.calc_matrix_camera(bpy.context.evaluated_depsgraph_get(), x=w, y=h)
json.dump({
    "width": w, "height": h, "fov_y_deg": cam_spec["fov_y"], "near": cd.clip_start, "far": cd.clip_end,
    "world_to_camera": [list(r) for r in w2c], "projection": [list(r) for r in proj],
    "convention": "matrices are column-vector (p_cam = M * p_world), rows listed top to bottom; camera looks down -Z, +Y up",
    "depth_channel": "ViewLayer.Depth.Z: planar view-space distance along the camera axis (positive)",
    "normal_channel": "ViewLayer.Normal.XYZ: world space, unit length",
    "color_channel": "ViewLayer.DiffCol.RGB: diffuse albedo",
    "ao_channel": "ViewLayer.AO.R: Cycles ray-traced ambient occlusion, distance %.3g m, %d samples per pixel" % (
        spec["ao_distance"], a.samples),
    "id_channels": "ViewLayer.IndexOB.X: pass_index (%s); Cryptomatte layer ViewLayer.CryptoObject (object names)" % (
        ", ".join("%s=%d" % (l, bpy.data.objects[l].pass_index) for l in labels)),
    "hidden": "%s_hidden.exr: the same frame with '%s' hidden from rendering; %s_ref.exr: its AO pass, with Depth.Z "
              "1e10 where this frame shows '%s'" % (os.path.basename(a.out), a.hide, os.path.basename(a.out), a.hide),
    "ao_distance": spec["ao_distance"], "engine": "cycles",
}, open(a.out + ".camera.json", "w"), indent=1)

# The reference as the referee reads it (Debian's python3-openimageio, which
# Debian's Blender imports from the system's Python).
import OpenImageIO as oiio

def channels(path, names):
    buf = oiio.ImageBuf(path)
    have = list(buf.spec().channelnames)
    px = buf.get_pixels(oiio.FLOAT)
    missing = [c for c in names if c not in have]
    if missing: sys.exit("%s: no channel %s (has %s)" % (path, missing, have))
    return [px[:, :, have.index(c)] for c in names]

(ids,) = channels(a.out + ".exr", ["ViewLayer.IndexOB.X"])
ao, z = channels(a.out + "_hidden.exr", ["ViewLayer.AO.R", "ViewLayer.Depth.Z"])
z = numpy.where(numpy.rint(ids) == hidden.pass_index, 1e10, z)
img = numpy.stack([ao, z], -1).astype(numpy.float32)
spec_out = oiio.ImageSpec(w, h, 2, oiio.FLOAT)
spec_out.channelnames = ("ViewLayer.AO.R", "ViewLayer.Depth.Z")
spec_out.attribute("compression", "zip")
spec_out.attribute("ImageDescription", "Cycles AO (%d spp, distance %g m) with '%s' hidden; Depth.Z 1e10 where the "
                   "full frame shows '%s'" % (a.samples, spec["ao_distance"], a.hide, a.hide))
o = oiio.ImageOutput.create(a.out + "_ref.exr")
o.open(a.out + "_ref.exr", spec_out); o.write_image(img); o.close()
print("REFERENCE %s_ref.exr: %d pixels of '%s' left out" % (a.out, int((numpy.rint(ids) == hidden.pass_index).sum()), a.hide))
