// Invocation ids with the dispatch's workgroups in spread order (shared/mrgi_shared.h
// spread_workgroup_index: on lavapipe each worker thread runs a contiguous run of workgroups,
// so neighbouring runs must cover the whole grid for the threads to finish together). For 2D
// dispatches with one layer of workgroups (z = 1) and 1D ones; include after
// shared/mrgi_shared.h.
#ifndef MRGI_WORKGROUP_ORDER_GLSL
#define MRGI_WORKGROUP_ORDER_GLSL

ivec2 spread_workgroup_id() {
  ivec2 groups = ivec2(gl_NumWorkGroups.xy);
  int k = int(gl_WorkGroupID.x) + groups.x * int(gl_WorkGroupID.y);
  int t = spread_workgroup_index(k, groups.x * groups.y);
  int y = div_nonneg1(t, groups.x);
  return ivec2(t - y * groups.x, y);
}

// gl_WorkGroupID.x of a 1D dispatch (a tile list's entry), spread.
int spread_workgroup_index_1d() {
  return spread_workgroup_index(int(gl_WorkGroupID.x), int(gl_NumWorkGroups.x));
}

// gl_GlobalInvocationID.xy of the spread workgroup. A macro, not a function: glslang resolves
// gl_WorkGroupSize where a function is defined, and this file is included before the shader's
// local_size layout, where it is still (1, 1, 1).
#define spread_invocation_id() \
  (spread_workgroup_id() * ivec2(gl_WorkGroupSize.xy) + ivec2(gl_LocalInvocationID.xy))

#endif  // MRGI_WORKGROUP_ORDER_GLSL
