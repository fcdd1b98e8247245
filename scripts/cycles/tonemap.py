# An OpenEXR image to an 8-bit PNG as tracer writes one (film/tone_map.cpp): 1 - exp(-exposure L),
# then the sRGB transfer curve; so that two renderers' EXR files are shown the same way.
#   blender -b --factory-startup -noaudio --python tonemap.py -- in.exr out.png [exposure]
import math
import sys

import bpy

args = sys.argv[sys.argv.index('--') + 1:]
src, dst = args[0], args[1]
exposure = float(args[2]) if len(args) > 2 else 1.5


def display(x):
    if not x > 0.0:
        return 0.0
    m = 1.0 - math.exp(-exposure * x)
    return 12.92 * m if m <= 0.0031308 else 1.055 * m ** (1.0 / 2.4) - 0.055


img = bpy.data.images.load(src)
w, h = img.size
px = list(img.pixels)  # linear RGBA floats, rows from the bottom
out = bpy.data.images.new('png', w, h, alpha=False)
out.colorspace_settings.name = 'Non-Color'  # the bytes are the display values computed here
out.pixels = [display(v) if i % 4 != 3 else 1.0 for i, v in enumerate(px)]
out.filepath_raw = dst
out.file_format = 'PNG'
out.save()
