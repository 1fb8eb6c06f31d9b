#version 330 core
#include "colormap.glsl"

in vec2 v_corner;
in vec4 v_color;
flat in int v_kind;

uniform sampler2D u_font;
uniform int u_font_columns;
uniform ivec2 u_cell_texels;

layout(location = 0) out vec4 o_color;

void main() {
  if (v_kind == -1) {
    o_color = v_color;
    return;
  }
  if (v_kind == -2) {
    o_color = vec4(autogravColormap(v_corner.x), v_color.a);
    return;
  }
  ivec2 cell = ivec2(v_kind % u_font_columns, v_kind / u_font_columns) * u_cell_texels;
  ivec2 texel = ivec2(min(v_corner * vec2(u_cell_texels), vec2(u_cell_texels) - 0.001));
  float coverage = texelFetch(u_font, cell + texel, 0).r;
  if (coverage < 0.5) discard;
  o_color = v_color;
}
