#version 450
// Pull-push of the ISMs (gi/ism.h), push: the holes of level m (-1) take their parent's value in
// level m + 1 (which may be a hole too), in place.
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rg32f) uniform readonly image2D coarser;
layout(set = 0, binding = 1, rg32f) uniform image2D finer;
layout(push_constant) uniform Params { ivec4 size; } params;  // x: the finer level's used side

void main() {
  ivec2 t = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(t, ivec2(params.size.x)))) return;
  vec2 d = imageLoad(finer, t).xy;
  if (d.x >= 0.0f && d.y >= 0.0f) return;
  vec2 parent = imageLoad(coarser, t / 2).xy;
  imageStore(finer, t, vec4(d.x >= 0.0f ? d.x : parent.x, d.y >= 0.0f ? d.y : parent.y, 0.0f, 0.0f));
}
