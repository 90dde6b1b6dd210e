// One propagation step's gather for the cell `c` of an n^3 volume (gi/lpv_propagate.comp, one
// step a dispatch; gi/lpv_propagate_local.comp, every step in one workgroup), spliced into the
// including shader's main(): it reads c, n, damping and own_r/g/b (the cell's previous step),
// adds into r, g, b, and loads a neighbour's previous step with LPV_LOAD_R/G/B(q), which the
// includer defines (an image or shared memory).
// lpv_gather_from for each neighbour, its face loop spelled out with constant axes so that
// every direction, SH basis and lobe is a constant (a loop over k and f kept them as run-time
// work: 12 ms a step at 32^3 on lavapipe, against about 4 unrolled). A neighbour outside the
// used volume reads as zero (no light from outside).
// With LPV_GATHER_ONE defined, one channel only: `r` from LPV_LOAD_R and own_r (a workgroup per
// colour channel, lpv_propagate_local.comp).
#ifdef LPV_GATHER_ONE
#define LPV_FACE(A, F) r += lpv_gather_face(sr, own_r, A, F, damping);
#define LPV_NEIGHBOUR(A, F1, F2, F3, F4, F5) \
  { \
    const ivec3 q = c + ivec3(A); \
    const bool inside = all(greaterThanEqual(q, ivec3(0))) && all(lessThan(q, ivec3(n))); \
    const vec4 sr = inside ? LPV_LOAD_R(q) : vec4(0.0); \
    LPV_FACE(A, F1) LPV_FACE(A, F2) LPV_FACE(A, F3) LPV_FACE(A, F4) LPV_FACE(A, F5) \
  }
#else
#define LPV_FACE(A, F) \
  r += lpv_gather_face(sr, own_r, A, F, damping); \
  g += lpv_gather_face(sg, own_g, A, F, damping); \
  b += lpv_gather_face(sb, own_b, A, F, damping);
#define LPV_NEIGHBOUR(A, F1, F2, F3, F4, F5) \
  { \
    const ivec3 q = c + ivec3(A); \
    const bool inside = all(greaterThanEqual(q, ivec3(0))) && all(lessThan(q, ivec3(n))); \
    const vec4 sr = inside ? LPV_LOAD_R(q) : vec4(0.0); \
    const vec4 sg = inside ? LPV_LOAD_G(q) : vec4(0.0); \
    const vec4 sb = inside ? LPV_LOAD_B(q) : vec4(0.0); \
    LPV_FACE(A, F1) LPV_FACE(A, F2) LPV_FACE(A, F3) LPV_FACE(A, F4) LPV_FACE(A, F5) \
  }
#endif
  const vec3 px = vec3(1, 0, 0), nx = vec3(-1, 0, 0), py = vec3(0, 1, 0), ny = vec3(0, -1, 0);
  const vec3 pz = vec3(0, 0, 1), nz = vec3(0, 0, -1);
  LPV_NEIGHBOUR(px, nx, py, ny, pz, nz)
  LPV_NEIGHBOUR(nx, px, py, ny, pz, nz)
  LPV_NEIGHBOUR(py, px, nx, ny, pz, nz)
  LPV_NEIGHBOUR(ny, px, nx, py, pz, nz)
  LPV_NEIGHBOUR(pz, px, nx, py, ny, nz)
  LPV_NEIGHBOUR(nz, px, nx, py, ny, pz)
#undef LPV_NEIGHBOUR
#undef LPV_FACE
