"""Rasterizes screen-space triangles with Mesa's llvmpipe through a headless OpenGL context.

Usage: llvmpipe_raster.py WIDTH HEIGHT FRAMEBUFFER TRIANGLES OUT FLIP. TRIANGLES holds three vertices per
triangle, 16 bytes each, little endian: x and y in pixels (x right, y down, on the 1/256
grid), z in 0..1 (0 nearest) as float32, then the triangle's id as uint32 (0 is reserved
for the background). The triangles are drawn in file order with the depth test LESS (an
equal depth keeps the earlier triangle), no culling and no blending, into a square RGBA8
framebuffer of FRAMEBUFFER pixels a side (a power of two) cleared to id 0 and depth 1, with
the WIDTHxHEIGHT image at its centre: triangles that cross the image's border stay inside
GL's viewport, so GL never clips them (clipping would give them new float vertices off the
1/256 grid). OUT receives the image's ids, one little-endian uint32 per pixel, rows from the
top. FLIP 1: window y is the pixel y (GL's bottom row is sortsim's top row); FLIP -1:
window y runs up, the image upright in GL's own orientation. Prints the renderer's name and
the wall time as JSON. Exits with 3 and names the module when moderngl is not installed.
"""

import json
import sys
import time

try:
    import moderngl
except ImportError as missing:
    print(f"missing-module: {missing.name}", file=sys.stderr)
    sys.exit(3)

VERTEX = """
#version 330
uniform vec2 offset;
uniform float framebuffer;
uniform float flip;
in vec3 position;
in uint id;
flat out uint v_id;
void main() {
    vec2 ndc = (position.xy + offset) / framebuffer * 2.0 - 1.0;
    gl_Position = vec4(ndc.x, flip * ndc.y, position.z * 2.0 - 1.0, 1.0);
    v_id = id;
}
"""

FRAGMENT = """
#version 330
flat in uint v_id;
out vec4 colour;
void main() {
    colour = vec4(float(v_id & 255u), float((v_id >> 8) & 255u),
                  float((v_id >> 16) & 255u), 255.0) / 255.0;
}
"""


def main(width, height, side, triangles, out, flip):
    began = time.perf_counter()
    ctx = moderngl.create_standalone_context(backend="egl")
    program = ctx.program(vertex_shader=VERTEX, fragment_shader=FRAGMENT)
    left, bottom = (side - width) // 2, (side - height) // 2
    program["offset"].value = (float(left), float(bottom))
    program["framebuffer"].value = float(side)
    program["flip"].value = flip
    with open(triangles, "rb") as f:
        data = f.read()
    vao = ctx.vertex_array(program, [(ctx.buffer(data), "3f4 u4", "position", "id")])
    fbo = ctx.framebuffer(color_attachments=[ctx.renderbuffer((side, side), 4)],
                          depth_attachment=ctx.depth_renderbuffer((side, side)))
    fbo.use()
    ctx.viewport = (0, 0, side, side)
    ctx.disable(moderngl.CULL_FACE | moderngl.BLEND)
    ctx.enable(moderngl.DEPTH_TEST)
    ctx.depth_func = "<"
    fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
    vao.render(moderngl.TRIANGLES)
    rgba = fbo.read(viewport=(left, bottom, width, height), components=4, alignment=1)
    rows = [rgba[y * width * 4:(y + 1) * width * 4] for y in range(height)]
    if flip < 0:
        rows.reverse()
    ids = bytearray()
    for row in rows:
        for x in range(width):
            r, g, b = row[4 * x], row[4 * x + 1], row[4 * x + 2]
            ids += (r | g << 8 | b << 16).to_bytes(4, "little")
    with open(out, "wb") as f:
        f.write(ids)
    json.dump({"renderer": ctx.info["GL_RENDERER"], "wall_s": time.perf_counter() - began},
              sys.stdout)


if __name__ == "__main__":
    main(int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]), sys.argv[4], sys.argv[5],
         float(sys.argv[6]))
