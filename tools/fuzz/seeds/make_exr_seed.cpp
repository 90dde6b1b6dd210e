// Writes corpus/hdr/tiny_4x2.exr: g++ make_exr_seed.cpp -lz -o /tmp/e && /tmp/e ../corpus/hdr/tiny_4x2.exr
#define TINYEXR_IMPLEMENTATION
#define TINYEXR_USE_MINIZ 0
#include <zlib.h>
#include <tinyexr.h>
int main(int, char** argv) {
  float rgb[4 * 2 * 3];
  for (int i = 0; i < 24; ++i) rgb[i] = 0.1f * float(i);
  const char* err = nullptr;
  return SaveEXR(rgb, 4, 2, 3, 0, argv[1], &err);
}
