# Blender (3.4) side of scripts/compare-cycles.sh: builds the Driftscape
# frame in Cycles and renders it. Run as
#   blender -b --factory-startup --python scripts/cycles_scene.py -- ARGS
# ARGS (key=value): dem (raw float32 rows, north first), width, height (DEM
# vertices), gt (the DEM's geotransform, 6 numbers by commas), sidecar
# (drift render --sidecar JSON: camera, sun, local origin), w, h (image),
# spp, seed, threads, altitude (camera metres above sea level), out (EXR),
# sun (the sun lamp's irradiance, W/m^2; 0: calibrate, see below).
#
# The scene is the comparison's plain ground (docs/rendering.md, "Against
# Cycles"): a grid mesh of the DEM's cell centres split along the same
# diagonal as Driftscape's (v1-v3), grey Lambertian ground of albedo 0.3,
# Nishita sky without its sun disc plus a Sun lamp of the disc's irradiance
# and angle, 3 diffuse bounces, no clamping, a 1-pixel box filter, no
# denoiser and no adaptive sampling.
import json
import math
import sys
import time

import bpy
import numpy as np

args = dict(a.split("=", 1) for a in sys.argv[sys.argv.index("--") + 1:])
side = json.load(open(args["sidecar"]))
origin = side["origin"]
W, H = int(args["w"]), int(args["h"])

scene = bpy.context.scene
for o in list(bpy.data.objects):
    bpy.data.objects.remove(o)

cy = scene.cycles
scene.render.engine = "CYCLES"
cy.device = "CPU"
cy.samples = int(args["spp"])
cy.seed = int(args["seed"])
cy.use_adaptive_sampling = False
cy.use_denoising = False
cy.max_bounces = 4
cy.diffuse_bounces = 3
cy.glossy_bounces = 0
cy.transmission_bounces = 0
cy.volume_bounces = 0
cy.transparent_max_bounces = 0
cy.sample_clamp_direct = 0.0
cy.sample_clamp_indirect = 0.0
cy.caustics_reflective = False
cy.caustics_refractive = False
cy.pixel_filter_type = "BOX"
cy.filter_width = 1.0
scene.render.threads_mode = "FIXED"
scene.render.threads = int(args["threads"])
scene.render.resolution_x, scene.render.resolution_y = W, H
scene.render.resolution_percentage = 100
scene.render.use_persistent_data = False
scene.view_settings.view_transform = "Standard"
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_mode = "RGB"
scene.render.image_settings.color_depth = "32"

# Sky: Nishita at the camera's altitude, the sun where Driftscape has it.
# Cycles puts Nishita's sun at (-sin r cos e, cos r cos e, sin e) for
# rotation r: from the sun's direction (x east, y north, z up) back to r.
sun = side["sun"]["direction"]
elevation = math.asin(max(-1.0, min(1.0, sun[2])))
rotation = math.atan2(-sun[0], sun[1])
world = bpy.data.worlds.new("sky")
scene.world = world
world.use_nodes = True
nodes = world.node_tree.nodes
sky = nodes.new("ShaderNodeTexSky")
sky.sky_type = "NISHITA"
sky.sun_elevation = elevation
sky.sun_rotation = rotation
sky.altitude = max(0.0, float(args["altitude"]))
sky.sun_size = math.radians(0.53)
world.node_tree.links.new(sky.outputs["Color"], nodes["Background"].inputs["Color"])


def ground_material(albedo):
    m = bpy.data.materials.new("ground")
    m.use_nodes = True
    bsdf = m.node_tree.nodes["Principled BSDF"]
    m.node_tree.nodes.remove(bsdf)
    diffuse = m.node_tree.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (albedo, albedo, albedo, 1.0)
    diffuse.inputs["Roughness"].default_value = 0.0
    out = m.node_tree.nodes["Material Output"]
    m.node_tree.links.new(diffuse.outputs["BSDF"], out.inputs["Surface"])
    return m


def add_grid_mesh(name, xs, ys, z, quads_by_diagonal):
    """A mesh of len(ys) x len(xs) vertices, two triangles a cell: v0 v1 v3
    and v2 v3 v1 (v0 = (c, r), v1 = (c + 1, r), v2 = (c + 1, r + 1),
    v3 = (c, r + 1)), Driftscape's diagonal."""
    ny, nx = z.shape
    X, Y = np.meshgrid(xs, ys)
    co = np.stack([X, Y, z], axis=-1).astype(np.float32).reshape(-1)
    idx = np.arange(nx * ny, dtype=np.int32).reshape(ny, nx)
    v0, v1 = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
    v2, v3 = idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    tris = np.empty((v0.size * 2, 3), dtype=np.int32)
    tris[0::2] = np.stack([v0, v1, v3], axis=1)
    tris[1::2] = np.stack([v2, v3, v1], axis=1)
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(nx * ny)
    mesh.vertices.foreach_set("co", co)
    mesh.loops.add(tris.size)
    mesh.loops.foreach_set("vertex_index", tris.reshape(-1))
    mesh.polygons.add(tris.shape[0])
    mesh.polygons.foreach_set("loop_start", np.arange(0, tris.size, 3, dtype=np.int32))
    mesh.polygons.foreach_set("loop_total", np.full(tris.shape[0], 3, dtype=np.int32))
    mesh.polygons.foreach_set("use_smooth", np.ones(tris.shape[0], dtype=bool))
    mesh.update(calc_edges=True)
    obj = bpy.data.objects.new(name, mesh)
    scene.collection.objects.link(obj)
    return obj


def sun_lamp(irradiance):
    lamp = bpy.data.lights.new("sun", type="SUN")
    lamp.energy = irradiance  # W/m^2 on a surface facing it
    lamp.angle = math.radians(0.53)
    obj = bpy.data.objects.new("sun", lamp)
    scene.collection.objects.link(obj)
    # A sun lamp shines along its -Z: its Z is the direction to the sun.
    from mathutils import Vector

    obj.rotation_euler = Vector(sun).to_track_quat("Z", "Y").to_euler()
    return obj


start = time.time()
if float(args["sun"]) <= 0.0:
    # Calibration: Nishita's sun disc's irradiance at this altitude, from a
    # white Lambertian plane seen straight down, rendered with the disc and
    # without (radiance E cos(zenith) / pi more with it).
    plane_z = np.zeros((2, 2), dtype=np.float32)
    add_grid_mesh("plane", np.array([-1e3, 1e3]), np.array([1e3, -1e3]), plane_z, True)
    scene.objects["plane"].data.materials.append(ground_material(1.0))
    cam = bpy.data.cameras.new("top")
    cam.type = "ORTHO"
    cam.ortho_scale = 10.0
    co = bpy.data.objects.new("top", cam)
    co.location = (0.0, 0.0, 100.0)
    scene.collection.objects.link(co)
    scene.camera = co
    scene.render.resolution_x = scene.render.resolution_y = 16
    cy.samples = 1024
    means = []
    for disc in (True, False):
        sky.sun_disc = disc
        scene.render.filepath = args["out"] + (".disc.exr" if disc else ".nodisc.exr")
        bpy.ops.render.render(write_still=True)
        img = bpy.data.images.load(scene.render.filepath)
        px = np.array(img.pixels[:]).reshape(-1, 4)[:, :3]
        means.append(px.mean(axis=0))
    e = (means[0] - means[1]) * math.pi / max(math.sin(elevation), 1e-3)
    # The lamp is white: the disc's luminance (Rec. 709 weights).
    print("cycles: sun_irradiance %.6g" % float(0.2126 * e[0] + 0.7152 * e[1] + 0.0722 * e[2]))
    sys.exit(0)

sky.sun_disc = False
sun_lamp(float(args["sun"]))

# The DEM: cell centres in the local frame (CRS less the sidecar's origin).
nx, ny = int(args["width"]), int(args["height"])
gt = [float(v) for v in args["gt"].split(",")]
z = np.fromfile(args["dem"], dtype="<f4").reshape(ny, nx) - np.float32(origin[2])
xs = gt[0] + (np.arange(nx) + 0.5) * gt[1] - origin[0]
ys = gt[3] + (np.arange(ny) + 0.5) * gt[5] - origin[1]
ground = add_grid_mesh("dem", xs, ys, z, True)
ground.data.materials.append(ground_material(0.3))

# The camera: the sidecar's pose (OpenCV axes: x right, y down, z forward)
# turned to Blender's (x right, y up, looking along -z), its vertical field.
from mathutils import Matrix

R = side["camera"]["rotation"]
pos = side["camera"]["position"]
cols = [[R[i][k] for i in range(3)] for k in range(3)]  # OpenCV axes in the CRS
bx, by, bz = cols[0], [-v for v in cols[1]], [-v for v in cols[2]]
m = Matrix(((bx[0], by[0], bz[0], pos[0] - origin[0]), (bx[1], by[1], bz[1], pos[1] - origin[1]),
            (bx[2], by[2], bz[2], pos[2] - origin[2]), (0, 0, 0, 1)))
cam = bpy.data.cameras.new("camera")
cam.sensor_fit = "VERTICAL"
cam.angle_y = math.radians(side["intrinsics"]["vertical_fov_deg"])
cam.clip_start = 1.0
cam.clip_end = 1e7
camera = bpy.data.objects.new("camera", cam)
camera.matrix_world = m
scene.collection.objects.link(camera)
scene.camera = camera
print("cycles: setup_s %.3f" % (time.time() - start))

scene.render.filepath = args["out"]
start = time.time()
bpy.ops.render.render(write_still=True)
print("cycles: render_s %.3f" % (time.time() - start))
