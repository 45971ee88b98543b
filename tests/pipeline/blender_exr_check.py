import bpy, sys
# Usage: blender -b --factory-startup --python tests/pipeline/blender_exr_check.py -- FRAME.exr OBJECT
# Opens a drift render's EXR in Blender's compositor (multilayer image node,
# Cryptomatte node by name) and compares Blender's matte of OBJECT with the
# coverage decoded here from the CryptoObject layers (docs/rendering.md).
# Needs oiiotool. Manual: Blender is not a build dependency.
import os, tempfile
argv = sys.argv[sys.argv.index("--") + 1:]
path, object_name = os.path.abspath(argv[0]), argv[1]
work = tempfile.mkdtemp()
img = bpy.data.images.load(path)
pass
print("BLCHECK image type:", img.type, "size:", tuple(img.size))
scene = bpy.context.scene
scene.use_nodes = True
tree = scene.node_tree
for n in list(tree.nodes):
    tree.nodes.remove(n)
node = tree.nodes.new("CompositorNodeImage")
node.image = img
print("BLCHECK image node outputs:", [o.name for o in node.outputs if o.enabled])
crypto = tree.nodes.new("CompositorNodeCryptomatteV2")
crypto.source = "IMAGE"
crypto.image = img
for name in ("CryptoObject", "CryptoMaterial", "CryptoAsset"):
    try:
        crypto.layer_name = name
        print("BLCHECK cryptomatte layer", name, "accepted:", crypto.layer_name)
    except Exception as e:
        print("BLCHECK cryptomatte layer", name, "refused:", e)
crypto.layer_name = "CryptoObject"
crypto.matte_id = object_name
print("BLCHECK matte_id:", crypto.matte_id)
tree.links.new(node.outputs["Combined"], crypto.inputs["Image"])
comp = tree.nodes.new("CompositorNodeComposite")
out = tree.nodes.new("CompositorNodeOutputFile")
out.base_path = work + "/"
out.format.file_format = "OPEN_EXR"
out.file_slots[0].path = "matte_"
tree.links.new(crypto.outputs["Matte"], out.inputs[0])
tree.links.new(crypto.outputs["Matte"], comp.inputs["Image"])
scene.render.resolution_x, scene.render.resolution_y = img.size[0], img.size[1]
scene.render.resolution_percentage = 100
scene.render.engine = "BLENDER_WORKBENCH"
scene.render.filepath = work + "/composite.png"
bpy.ops.render.render(write_still=True)
import subprocess, struct, re, json
def dump(path, chans):
    subprocess.run(["oiiotool", path, "--ch", chans, "-o", work + "/dump.exr"], check=True)
    out = subprocess.run(["oiiotool", "--dumpdata", work + "/dump.exr"], capture_output=True, text=True).stdout
    px = {}
    for line in out.splitlines():
        m = re.match(r"\s*Pixel \((\d+), (\d+)\):\s*(.*)", line)
        if m: px[(int(m.group(1)), int(m.group(2)))] = [float(v) for v in m.group(3).split()]
    return px
def crypto_float(h):
    bits = int(h, 16)
    exp = (bits >> 23) & 255
    if exp == 0 or exp == 255: bits ^= 1 << 23
    return struct.unpack("<f", struct.pack("<I", bits))[0]
info = subprocess.run(["oiiotool", "--info", "-v", path], capture_output=True, text=True).stdout
manifest = None
for line in info.splitlines():
    if "manifest" in line and '"' + object_name + '"' in line and "CryptoObject" in info:
        manifest = json.loads(line.split(": ", 1)[1][1:-1].replace('\\"', '"'))
        if object_name in manifest: break
hut = crypto_float(manifest[object_name])
ours = dump(path, "CryptoObject00.R,CryptoObject00.G,CryptoObject00.B,CryptoObject00.A,CryptoObject01.R,CryptoObject01.G,CryptoObject01.B,CryptoObject01.A")
theirs = dump(work + "/matte_0001.exr", "R")
worst = 0; n = 0; tot_o = tot_b = 0
for k, v in ours.items():
    cov = sum(v[i + 1] for i in range(0, 8, 2) if abs(v[i] - hut) <= 1e-6 * abs(hut))
    b = theirs[k][0]
    worst = max(worst, abs(cov - b)); tot_o += cov; tot_b += b; n += cov > 0
print("BLCHECK pixels", len(ours), "with", object_name, n, "sum ours %.4f blender %.4f max diff %.2e" % (tot_o, tot_b, worst))
