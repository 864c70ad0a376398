#!/usr/bin/env python3
"""Writes the fuzz targets' seed corpora (fuzz/corpus/<target>/seed-*): small valid and
nearly valid files of each format, written here by hand from the specifications and the
loader tests' cases. Run from anywhere; needs Pillow for the image seeds
(`pip install pillow`). The fuzzer adds what it finds next to these."""

import base64
import io
import json
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))


def write(target, name, data):
    d = os.path.join(HERE, "corpus", target)
    os.makedirs(d, exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(d, "seed-" + name), "wb") as f:
        f.write(data)


# --- OBJ (+ MTL after a NUL byte) -------------------------------------------------------

QUAD = "v -1 -1 0 1 0 0\nv 1 -1 0 0 1 0\nv 1 1 0 0 0 1\nv -1 1 0 1 1 0\nf 1 2 3\nf 1 3 4\n"
OBJ = {
    "quad.obj": QUAD,
    "flat.obj": "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 0 -1\nv 2 1 0\n"
    "vn 0 0 1\nvn 1 0 0\nf 1//1 2//1 3//1 4//1\nf -3//-1 -2//-1 -1//-1\n",
    "uv.obj": "mtllib m.mtl\no box\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\ng front\nusemtl tex\n"
    "f 1/1/1 2/2/1 3/3/1 4/4/1\ns 1\n"
    "\0newmtl tex\nKa 0.1 0.1 0.1\nKd 0.8 0.7 0.6\nKs 0 0 0\nd 0.9\nillum 2\n"
    "map_Kd -s 1 1 1 t.png\nnewmtl other\nTr 0.25\nKe 1 0 0\n",
    "groups.obj": "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\ng a\nf 1 2 3\ng b\nf 1 3 4\n"
    "o c\nf 2 3 4\nl 1 2 3\np 1\n",
    "polygon.obj": "v 0 0 0\nv 2 0 0\nv 3 1 0\nv 2 2 0\nv 0 2 0\nv -1 1 0\nf 1 2 3 4 5 6\n",
    "mixed_colours.obj": "v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0 0 0 1\nf 1 2 3\n",
    "absent_indices.obj": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1 2/0/1 3//1\n",
    "points.obj": "# no faces\nv 0 0 0\nv 1 0 0\np 1 2\n",
    "bad_index.obj": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
    "bad_mtl.obj": "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n"
    "\0newmtl m\nKd 1 2\n",
}
for name, text in OBJ.items():
    write("obj", name, text)


# --- glTF JSON and GLB ------------------------------------------------------------------


def f32s(*v):
    return struct.pack("<%df" % len(v), *v)


def u16s(*v):
    return struct.pack("<%dH" % len(v), *v)


TRI = f32s(0, 0, 0, 1, 0, 0, 0, 1, 0)
UV = f32s(0, 0, 1, 0, 0, 1)
IDX = u16s(0, 1, 2) + b"\0\0"


def glb(doc, bin_chunk=b""):
    j = json.dumps(doc).encode()
    j += b" " * (-len(j) % 4)
    b = bin_chunk + b"\0" * (-len(bin_chunk) % 4)
    total = 12 + 8 + len(j) + (8 + len(b) if b else 0)
    out = b"glTF" + struct.pack("<II", 2, total) + struct.pack("<I", len(j)) + b"JSON" + j
    if b:
        out += struct.pack("<I", len(b)) + b"BIN\0" + b
    return out


def data_uri(b):
    return "data:application/octet-stream;base64," + base64.b64encode(b).decode()


def triangle(buffer, extra=None, prim=None, scenes=True):
    """A triangle with UVs and indices in one 68-byte buffer."""
    doc = {
        "asset": {"version": "2.0"},
        "nodes": [{"mesh": 0, "translation": [0, 0, -1]}],
        "meshes": [
            {
                "primitives": [
                    dict(
                        {"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2},
                        **(prim or {}),
                    )
                ]
            }
        ],
        "buffers": [buffer],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 24},
            {"buffer": 0, "byteOffset": 60, "byteLength": 6},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"},
            {"bufferView": 2, "componentType": 5123, "count": 3, "type": "SCALAR"},
        ],
    }
    if scenes:
        doc["scene"] = 0
        doc["scenes"] = [{"nodes": [0]}]
    doc.update(extra or {})
    return doc


BUF = TRI + UV + IDX
MATERIALS = {
    "materials": [
        {
            "pbrMetallicRoughness": {
                "baseColorFactor": [1, 0.5, 0.25, 1],
                "baseColorTexture": {
                    "index": 0,
                    "extensions": {"KHR_texture_transform": {"offset": [0.5, 0], "scale": [2, 2]}},
                },
            },
            "emissiveFactor": [1, 0.5, 0],
            "alphaMode": "MASK",
            "alphaCutoff": 0.3,
            "doubleSided": True,
            "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4}},
        },
        {"extensions": {"KHR_materials_unlit": {}}, "alphaMode": "BLEND"},
    ],
    "textures": [{"source": 0, "sampler": 0}],
    "images": [{"uri": "t.png"}],
    "samplers": [{"magFilter": 9728, "wrapS": 33071, "wrapT": 33648}],
    "extensionsUsed": ["KHR_texture_transform", "KHR_materials_emissive_strength",
                       "KHR_materials_unlit", "KHR_materials_clearcoat"],
}

GLTF = {
    "data_uri.gltf": triangle({"uri": data_uri(BUF), "byteLength": len(BUF)}),
    "external.gltf": triangle({"uri": "b.bin", "byteLength": 64}),
    "materials.gltf": triangle({"uri": data_uri(BUF), "byteLength": len(BUF)}, MATERIALS,
                               {"material": 0}),
    "no_scenes.gltf": triangle({"uri": data_uri(BUF), "byteLength": len(BUF)}, scenes=False),
    "empty_scene.gltf": {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{}]},
    "asset_only.gltf": {"asset": {"version": "2.0"}},
    "strip.gltf": triangle({"uri": data_uri(BUF), "byteLength": len(BUF)}, prim={"mode": 5}),
    "required.gltf": triangle({"uri": data_uri(BUF), "byteLength": len(BUF)},
                              {"extensionsUsed": ["KHR_draco_mesh_compression"],
                               "extensionsRequired": ["KHR_draco_mesh_compression"]}),
    "hierarchy.gltf": triangle(
        {"uri": data_uri(BUF), "byteLength": len(BUF)},
        {"nodes": [{"children": [1], "rotation": [0, 0.7071, 0, 0.7071]},
                   {"mesh": 0, "matrix": [2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 1, 2, 3, 1]}]}),
}
SPARSE_BUF = u16s(0, 1, 2) + b"\0\0" + f32s(2, 0, 0, 0, 3, 0, 1, 1, 1)
GLTF["sparse.gltf"] = {
    "asset": {"version": "2.0"},
    "scenes": [{"nodes": [0]}],
    "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
    "buffers": [{"uri": data_uri(SPARSE_BUF), "byteLength": len(SPARSE_BUF)}],
    "bufferViews": [{"buffer": 0, "byteLength": 6},
                    {"buffer": 0, "byteOffset": 8, "byteLength": 36}],
    "accessors": [{"componentType": 5126, "count": 3, "type": "VEC3",
                   "min": [0, 0, 0], "max": [2, 3, 1],
                   "sparse": {"count": 3,
                              "indices": {"bufferView": 0, "componentType": 5123},
                              "values": {"bufferView": 1}}}],
}
for name, doc in GLTF.items():
    write("gltf", name, json.dumps(doc, indent=1))

GLB = {
    "triangle.glb": glb(triangle({"byteLength": len(BUF)}), BUF),
    "materials.glb": glb(triangle({"byteLength": len(BUF)}, MATERIALS, {"material": 0}), BUF),
    "empty_scene.glb": glb({"asset": {"version": "2.0"}, "scenes": [{}]}),
    "external.glb": glb(triangle({"uri": "b.bin", "byteLength": 64})),
    "truncated.glb": glb(triangle({"byteLength": len(BUF)}), BUF)[:90],
}
for name, data in GLB.items():
    write("glb", name, data)


# --- Images -----------------------------------------------------------------------------

try:
    from PIL import Image
except ImportError:
    raise SystemExit("image seeds need Pillow: pip install pillow")


def image_bytes(img, fmt, **kw):
    out = io.BytesIO()
    img.save(out, fmt, **kw)
    return out.getvalue()


grad = Image.new("RGBA", (8, 6))
grad.putdata([(x * 32, y * 40, 128, 255 - x * 16) for y in range(6) for x in range(8)])
IMAGES = {
    "rgba.png": image_bytes(grad, "PNG"),
    "rgb.png": image_bytes(grad.convert("RGB"), "PNG"),
    "grey.png": image_bytes(grad.convert("L"), "PNG"),
    "grey_alpha.png": image_bytes(grad.convert("LA"), "PNG"),
    "palette.png": image_bytes(grad.convert("P"), "PNG"),
    "grey16.png": image_bytes(grad.convert("I;16"), "PNG"),
    "rgb.jpg": image_bytes(grad.convert("RGB"), "JPEG", quality=80),
    "grey.jpg": image_bytes(grad.convert("L"), "JPEG", quality=50),
    "progressive.jpg": image_bytes(grad.convert("RGB"), "JPEG", progressive=True),
}
for name, data in IMAGES.items():
    write("image", name, data)


# --- Depth maps (PFM, OpenEXR) -----------------------------------------------------------


def pfm(w, h, values, channels=1, little=True):
    head = ("Pf" if channels == 1 else "PF") + f"\n{w} {h}\n{-1.0 if little else 1.0}\n"
    fmt = ("<" if little else ">") + "f" * len(values)
    return head.encode() + struct.pack(fmt, *values)


def attr(name, kind, value):
    return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value


def exr(w, h, channels, values):
    """A minimal single-part scanline OpenEXR file: FLOAT channels, no compression,
    values[c][y * w + x] per channel (channels sorted by name, as the format stores them)."""
    chlist = b"".join(n.encode() + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for n in channels)
    box = struct.pack("<iiii", 0, 0, w - 1, h - 1)
    header = (attr("channels", "chlist", chlist + b"\0")
              + attr("compression", "compression", b"\0")
              + attr("dataWindow", "box2i", box)
              + attr("displayWindow", "box2i", box)
              + attr("lineOrder", "lineOrder", b"\0")
              + attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
              + attr("screenWindowCenter", "v2f", struct.pack("<ff", 0, 0))
              + attr("screenWindowWidth", "float", struct.pack("<f", 1.0))
              + b"\0")
    start = 8 + len(header) + 8 * h
    blocks, offsets = b"", []
    for y in range(h):
        row = b"".join(struct.pack("<" + "f" * w, *values[c][y * w:(y + 1) * w])
                       for c in range(len(channels)))
        offsets.append(start + len(blocks))
        blocks += struct.pack("<ii", y, len(row)) + row
    return (b"\x76\x2f\x31\x01" + struct.pack("<I", 2) + header
            + struct.pack("<" + "Q" * h, *offsets) + blocks)


INF = float("inf")
DEPTH = {
    "small.pfm": pfm(3, 2, [1.0, 2.5, INF, 4.0, 0.5, 1e-3]),
    "big_endian.pfm": pfm(2, 2, [1, 2, 3, 4], little=False),
    "rgb.pfm": pfm(1, 2, [7, 0, 0, 9, 0, 0], channels=3),
    "short.pfm": pfm(4, 4, [1.0] * 3),
    "grey.exr": exr(2, 2, ["Y"], [[1.0, 2.0, INF, 0.5]]),
    "rgb.exr": exr(3, 1, ["B", "G", "R"], [[1, 2, 3], [1, 2, 3], [1, 2, 3]]),
}
for name, data in DEPTH.items():
    write("float_image", name, data)

# --- transforms.json captures (the fuzz target's folder holds a.png 2x2, a.pfm 2x2,
# b.pfm 1x1) ------------------------------------------------------------------------------

POSE = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 3], [0, 0, 0, 1]]
FRAME = {"file_path": "./a", "depth_file_path": "a.pfm", "transform_matrix": POSE}
TRANSFORMS = {
    "nerf.json": {"camera_angle_x": 0.69, "frames": [FRAME]},
    "intrinsics.json": {"fl_x": 2.0, "fl_y": 2.1, "cx": 0.9, "cy": 1.1, "w": 2, "h": 2,
                        "near": 0.1, "far": 10, "frames": [FRAME, dict(FRAME, fl_x=3.0)]},
    "mismatch.json": {"camera_angle_x": 0.69,
                      "frames": [dict(FRAME, depth_file_path="b.pfm")]},
    "escape.json": {"camera_angle_x": 0.69, "frames": [dict(FRAME, file_path="../a.png")]},
    "singular.json": {"camera_angle_x": 0.69,
                      "frames": [dict(FRAME, transform_matrix=[[0] * 4] * 3 + [[0, 0, 0, 1]])]},
    "no_frames.json": {"camera_angle_x": 0.69, "frames": []},
}
for name, doc in TRANSFORMS.items():
    write("transforms", name, json.dumps(doc, indent=1))

print("seeds written under", os.path.join(HERE, "corpus"))
