// Side-by-side images of a bench run (images/SCENE.png beside report.md): per scene, the camera
// frame and the reference next to every technique level's output of the same frame, each labelled
// with its all-pixel RDE and sustained ms, so a reader sees what a figure in the tables looks like.
#pragma once
#include <optional>
#include <string>

#include "mrgi/image.h"
#include "mrgi/perf/bench.h"

namespace mrgi::perf {

// Width of the kept outputs and of every cell of a sheet, pixels.
inline constexpr int kSampleWidth = 256;

// The image averaged over boxes down to `width` pixels wide, its aspect kept (a 640 x 480 frame
// to 256 x 192); an image already no wider is copied.
ImageRGB8 thumbnail(const ImageRGB8& image, int width);
ImageRGB8 thumbnail(const ImageRGBA8& image, int width);

// The sheet for `scene`: a first row with the camera and the reference of the sampled frame, then
// one row per technique with its levels left to right (best first). Nothing when no entry of the
// scene kept a sample (the scene has no references).
std::optional<ImageRGB8> render_sample_sheet(const BenchResult& result, const std::string& scene);

// Where a scene's sheet goes in a bench output, relative to it: images/SCENE.png, a '/' in the
// scene's name (a suite's sub-folder) as '-'.
std::string sample_sheet_path(const std::string& scene);

}  // namespace mrgi::perf
