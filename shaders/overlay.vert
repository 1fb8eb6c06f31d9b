#version 330 core
// Screen-space quads for the readout: glyphs of the bitmap font, solid panels, the colour bar.
// Rectangles are in framebuffer pixels from the top-left corner.

layout(location = 0) in vec2 a_corner;   // (0, 0) top-left .. (1, 1) bottom-right
layout(location = 1) in vec4 i_rect_px;  // x, y, width, height
layout(location = 2) in vec4 i_color;
layout(location = 3) in float i_kind;    // >= 0: glyph cell; -1: solid; -2: colour ramp along x

uniform vec2 u_viewport_px;

out vec2 v_corner;
out vec4 v_color;
flat out int v_kind;

void main() {
  vec2 pixel = i_rect_px.xy + a_corner * i_rect_px.zw;
  vec2 ndc = vec2(2.0 * pixel.x / u_viewport_px.x - 1.0, 1.0 - 2.0 * pixel.y / u_viewport_px.y);
  v_corner = a_corner;
  v_color = i_color;
  v_kind = int(floor(i_kind + 0.5));
  gl_Position = vec4(ndc, 0.0, 1.0);
}
