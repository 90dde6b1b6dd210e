// Writes the JPEG seeds of corpus/texture (baseline 8x6, progressive 17x9, greyscale 8x8):
//   gcc make_jpeg_seeds.c -ljpeg -o /tmp/s
//   /tmp/s ../corpus/texture/baseline_8x6.jpg ../corpus/texture/progressive_17x9.jpg ../corpus/texture/gray_8x8.jpg
#include <stdio.h>
#include <jpeglib.h>
static void write_jpeg(const char* path, int w, int h, int progressive, int gray) {
  FILE* f = fopen(path, "wb");
  struct jpeg_compress_struct c; struct jpeg_error_mgr e;
  c.err = jpeg_std_error(&e); jpeg_create_compress(&c); jpeg_stdio_dest(&c, f);
  c.image_width = w; c.image_height = h; c.input_components = gray ? 1 : 3;
  c.in_color_space = gray ? JCS_GRAYSCALE : JCS_RGB;
  jpeg_set_defaults(&c); jpeg_set_quality(&c, 80, TRUE);
  if (progressive) jpeg_simple_progression(&c);
  jpeg_start_compress(&c, TRUE);
  unsigned char row[64 * 3];
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w * (gray ? 1 : 3); ++x) row[x] = (unsigned char)(x * 9 + y * 17);
    JSAMPROW r = row; jpeg_write_scanlines(&c, &r, 1);
  }
  jpeg_finish_compress(&c); jpeg_destroy_compress(&c); fclose(f);
}
int main(int argc, char** argv) {
  write_jpeg(argv[1], 8, 6, 0, 0);
  write_jpeg(argv[2], 17, 9, 1, 0);
  write_jpeg(argv[3], 8, 8, 0, 1);
  return 0;
}
