// Colour ramp for |G| shared by the map arrows and the legend: t = 0 (smallest magnitude) is deep
// blue, t = 1 (largest) is red, through cyan, green and amber, so that neighbouring magnitudes
// stay distinguishable on a dark background.
vec3 autogravColormap(float t) {
  const vec3 c0 = vec3(0.17, 0.27, 0.80);
  const vec3 c1 = vec3(0.10, 0.66, 0.86);
  const vec3 c2 = vec3(0.48, 0.83, 0.34);
  const vec3 c3 = vec3(0.99, 0.75, 0.18);
  const vec3 c4 = vec3(0.89, 0.20, 0.16);
  float s = clamp(t, 0.0, 1.0) * 4.0;
  if (s < 1.0) return mix(c0, c1, s);
  if (s < 2.0) return mix(c1, c2, s - 1.0);
  if (s < 3.0) return mix(c2, c3, s - 2.0);
  return mix(c3, c4, s - 3.0);
}
