"""Renders the views of a `seethru export --format mitsuba` with Mitsuba 3, and compares them
with seethru's own renders of the same scene if a `seethru render` folder is given.

    python tools/mitsuba/render_views.py out/das.xml [--width 320] [--spp 64] \
        [--seethru out/render] [--out out/mitsuba]

Needs `pip install mitsuba numpy`. Writes <view>.exr (linear) and <view>.png (sRGB) per view.
With --seethru, renders at the size of seethru's <view>.exr and prints, per view, the ratio of
the mean colour over the pixels that show an object (sky excluded: Mitsuba's sky is seethru's
ambient light, not its gradient and clouds) and the mean absolute difference.
"""

import argparse
import os

import mitsuba as mi
import numpy as np

VIEWS = ["truth", "occluded", "frontal", "back"]


def srgb8(linear):
    c = np.clip(linear, 0.0, 1.0)
    c = np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1 / 2.4) - 0.055)
    return (c * 255 + 0.5).astype(np.uint8)


def seethru_frame(path):
    """Colour (linear RGB, in units of the scene's white) and object ids of a seethru EXR,
    each channel found by its name (a layer's channels are stored in no fixed order)."""
    bitmap = mi.Bitmap(path)
    channels = {}
    for layer, b in bitmap.split():
        values = np.array(b)
        values = values.reshape(values.shape[0], values.shape[1], -1)
        for k, field in enumerate(b.struct_()):
            name = field.name if layer == "<root>" else f"{layer}.{field.name}"
            channels[name] = values[..., k]
    color = np.stack([channels["R"], channels["G"], channels["B"]], axis=-1)
    # A photometric scene's EXR holds cd/m²; the export's light is in units of its white.
    metadata = bitmap.metadata()
    white = metadata.get("seethru_white_cd_m2") if "seethru_white_cd_m2" in metadata.keys() else 1.0
    ids = channels.get("id.object", channels.get("object_id.id"))
    return color / white, ids


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", help="the exported <stem>.xml")
    parser.add_argument("--width", type=int, help="image width (the height keeps the aspect)")
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--seethru", help="a `seethru render` output folder to compare with")
    parser.add_argument("--out", default="mitsuba")
    parser.add_argument("--variant", default="scalar_rgb")
    args = parser.parse_args()
    mi.set_variant(args.variant)
    os.makedirs(args.out, exist_ok=True)
    stem = args.scene[: -len(".xml")]
    for view in VIEWS:
        reference = None
        if args.seethru:
            reference = seethru_frame(os.path.join(args.seethru, f"{view}.exr"))
            height, width = reference[0].shape[:2]
        else:
            scene = mi.load_file(f"{stem}.{view}.xml")
            width, height = scene.sensors()[0].film().size()
            if args.width:
                width, height = args.width, max(1, round(height * args.width / width))
        scene = mi.load_file(f"{stem}.{view}.xml", spp=args.spp, width=width, height=height)
        image = np.array(mi.render(scene))[..., :3]
        mi.Bitmap(image).write(os.path.join(args.out, f"{view}.exr"))
        mi.Bitmap(srgb8(image)).write(os.path.join(args.out, f"{view}.png"))
        if reference is None:
            print(f"{view}: {width}x{height}")
            continue
        color, ids = reference
        objects = ids > 0
        ratio = image[objects].mean(axis=0) / color[objects].mean(axis=0)
        difference = np.abs(image[objects] - color[objects]).mean() / color[objects].mean()
        print(
            f"{view}: {width}x{height}, {objects.mean():.0%} of pixels show objects: "
            f"mean colour Mitsuba/seethru {np.round(ratio, 3)}, "
            f"mean |difference| {difference:.3f} of the mean"
        )


if __name__ == "__main__":
    main()
