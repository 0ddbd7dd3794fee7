"""Sets up one seethru view in Blender from a `seethru export --format gltf` file, and
optionally renders it with Cycles.

    blender --background --python tools/blender/seethru_view.py -- out/das.glb --view truth \
        [--render truth.exr] [--samples 64] [--width 320]

(or, with Blender as a Python module, `python tools/blender/seethru_view.py out/das.glb ...`).

What it sets up, from the glTF and its extras:
- the import with raw light units, so that the sun's strength is the irradiance seethru
  shades with (×π, as Blender's diffuse BSDF divides by π);
- the world: seethru's ambient light as two uniform hemispheres (`sky_up_radiance` above the
  horizon, `sky_down_radiance` below: exactly seethru's ambient on an unoccluded surface);
- the view's camera as the scene camera, and its resolution;
- the objects of the view: others are excluded from the render, as seethru leaves them out of
  that view (e.g. the driver's head in `truth`); objects with `casts_shadow` false cast none;
- Cycles with direct light only (seethru has no interreflections) and a box pixel filter.
"""

import argparse
import sys

import bpy

VIEW_CAMERA = {"truth": "driver", "occluded": "driver", "frontal": "frontal", "back": "back"}


def linear_float_texture(image):
    """Replaces an 8-bit sRGB image by a float image of its linear values."""
    if image.is_float or image.colorspace_settings.name != "sRGB":
        return
    w, h = image.size
    srgb = list(image.pixels[:])
    linear = [c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4 for c in srgb]
    for i in range(3, len(linear), 4):
        linear[i] = srgb[i]
    copy = bpy.data.images.new(image.name + " linear", w, h, alpha=True, float_buffer=True)
    copy.colorspace_settings.name = "Linear Rec.709"
    copy.pixels[:] = linear
    copy.pack()
    image.user_remap(copy)


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("glb")
    parser.add_argument("--view", choices=sorted(VIEW_CAMERA), default="truth")
    parser.add_argument("--render", help="render to this file (.exr: linear, .png: sRGB)")
    parser.add_argument("--samples", type=int, default=64)
    parser.add_argument("--width", type=int, help="image width (the height keeps the aspect)")
    args = parser.parse_args(argv)

    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=args.glb, export_import_convert_lighting_mode="RAW")
    scene = bpy.context.scene
    info = scene["seethru"].to_dict()

    # The world: two hemispheres split at the horizon (Blender's up is +Z).
    world = bpy.data.worlds.new("seethru sky")
    world.use_nodes = True
    nodes, links = world.node_tree.nodes, world.node_tree.links
    background = nodes["Background"]
    coords = nodes.new("ShaderNodeTexCoord")
    split = nodes.new("ShaderNodeSeparateXYZ")
    above = nodes.new("ShaderNodeMath")
    above.operation = "GREATER_THAN"
    above.inputs[1].default_value = 0.0
    mix = nodes.new("ShaderNodeMix")
    mix.data_type = "RGBA"
    mix.inputs["A"].default_value = (*info["sky_down_radiance"], 1.0)
    mix.inputs["B"].default_value = (*info["sky_up_radiance"], 1.0)
    links.new(coords.outputs["Generated"], split.inputs["Vector"])
    links.new(split.outputs["Z"], above.inputs[0])
    links.new(above.outputs["Value"], mix.inputs["Factor"])
    links.new(mix.outputs["Result"], background.inputs["Color"])
    background.inputs["Strength"].default_value = 1.0
    scene.world = world

    # Cycles filters 8-bit textures before decoding sRGB; seethru filters linear texels.
    for image in list(bpy.data.images):
        linear_float_texture(image)

    camera = bpy.data.objects[VIEW_CAMERA[args.view]]
    scene.camera = camera
    width, height = camera["resolution"]
    if args.width:
        width, height = args.width, max(1, round(height * args.width / width))
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    for obj in scene.objects:
        if "seethru_id" in obj:
            obj.hide_render = args.view not in list(obj["views"])
            obj.visible_shadow = bool(obj["casts_shadow"])

    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = args.samples
    scene.cycles.max_bounces = 0
    scene.cycles.pixel_filter_type = "BOX"
    scene.view_settings.view_transform = "Standard"
    if args.render:
        exr = args.render.lower().endswith(".exr")
        scene.render.image_settings.file_format = "OPEN_EXR" if exr else "PNG"
        scene.render.filepath = args.render
        bpy.ops.render.render(write_still=True)


if __name__ == "__main__":
    main(sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else sys.argv[1:])
