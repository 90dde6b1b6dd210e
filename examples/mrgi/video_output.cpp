#include "video_output.h"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <vector>

namespace mrgi::tool {
namespace fs = std::filesystem;
namespace {

std::string extension(const std::string& path) {
  std::string e = fs::path(path).extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return e;
}
bool is_apng(const std::string& e) { return e == ".png" || e == ".apng"; }
bool is_encoded(const std::string& e) { return e == ".mp4" || e == ".mkv" || e == ".webm"; }

bool ffmpeg_on_path() {
  const char* path = std::getenv("PATH");
  if (!path) return false;
  std::stringstream dirs(path);
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    std::error_code ec;
    if (!dir.empty() && fs::is_regular_file(fs::path(dir) / "ffmpeg", ec)) return true;
  }
  return false;
}

// Single quotes for sh, with any ' in the name closed, escaped and reopened.
std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

}  // namespace

double capture_fps(const std::vector<double>& timestamps) {
  std::vector<double> d;
  for (size_t i = 1; i < timestamps.size(); ++i)
    if (timestamps[i] > timestamps[i - 1]) d.push_back(timestamps[i] - timestamps[i - 1]);
  if (d.empty()) return 30.0;
  std::nth_element(d.begin(), d.begin() + std::ptrdiff_t(d.size() / 2), d.end());
  const double fps = 1.0 / d[d.size() / 2];
  return std::clamp(fps, 0.1, 1000.0);
}

Status VideoOutput::check(const std::string& path, const std::string& out_dir) {
  const std::string e = extension(path);
  if (!is_apng(e) && !is_encoded(e))
    return fail(ErrorKind::BadUsage, "--video " + path + ": the name must end in .png or .apng (animated PNG), "
                                     "or .mp4, .mkv or .webm (with ffmpeg)");
  if (is_encoded(e) && !ffmpeg_on_path())
    return fail(ErrorKind::BadUsage, "--video " + path + ": writing " + e + " needs the ffmpeg program (Debian "
                                     "package ffmpeg), not found on PATH; --video NAME.png writes an animated PNG");
  // The output folder is replaced as a whole at the end (replay_output.h): a clip inside it
  // would be lost.
  std::error_code ec;
  const fs::path clip = fs::weakly_canonical(fs::absolute(path), ec);
  const fs::path dir = fs::weakly_canonical(fs::absolute(out_dir), ec);
  const std::string c = clip.string(), d = dir.string() + "/";
  if (c.compare(0, d.size(), d) == 0)
    return fail(ErrorKind::BadUsage, "--video " + path + ": must not be inside the --out folder " + out_dir +
                                     " (it is replaced whole when the replay finishes)");
  if (clip.has_parent_path() && !fs::is_directory(clip.parent_path(), ec))
    return fail(ErrorKind::BadUsage, "--video " + path + ": folder " + clip.parent_path().string() + " does not exist");
  return ok_status();
}

Expected<VideoOutput> VideoOutput::create(const std::string& path, int width, int height, double fps) {
  VideoOutput v;
  v.path_ = path;
  v.width_ = width;
  v.height_ = height;
  const std::string e = extension(path);
  if (is_apng(e)) {
    auto w = AnimatedPngWriter::create(path, width, height, fps);
    if (!w) return w.error();
    v.apng_.emplace(std::move(*w));
    return v;
  }
  // The partial keeps the extension: ffmpeg picks the container by it.
  v.partial_ = (fs::path(path).parent_path() / (".partial-" + fs::path(path).filename().string())).string();
  const std::string codec = e == ".webm" ? "-c:v libvpx-vp9 -b:v 0 -crf 32" : "-c:v libx264 -preset fast -crf 18";
  std::ostringstream cmd;
  cmd << "ffmpeg -nostdin -y -loglevel error -f rawvideo -pix_fmt rgba -s " << width << "x" << height
      << " -framerate " << fps << " -i - " << codec << " -pix_fmt yuv420p " << shell_quote(v.partial_);
  v.pipe_ = popen(cmd.str().c_str(), "w");
  if (!v.pipe_) return fail(ErrorKind::Device, "--video " + path + ": cannot start ffmpeg: " + std::strerror(errno));
  return v;
}

VideoOutput::VideoOutput(VideoOutput&& o) noexcept
    : path_(std::move(o.path_)), partial_(std::move(o.partial_)), width_(o.width_), height_(o.height_),
      apng_(std::move(o.apng_)), pipe_(o.pipe_) {
  o.pipe_ = nullptr;
  o.apng_.reset();
}

VideoOutput::~VideoOutput() {
  if (pipe_) {  // never finished: nothing is left behind
    pclose(pipe_);
    std::error_code ec;
    fs::remove(partial_, ec);
  }
}

Status VideoOutput::add(const ImageRGBA8& frame) {
  if (apng_) return apng_->add(frame);
  if (!pipe_) return fail(ErrorKind::BadUsage, "--video " + path_ + ": already finished");
  if (frame.width != width_ || frame.height != height_)
    return fail(ErrorKind::BadUsage, "--video " + path_ + ": frame of another size");
  if (std::fwrite(frame.data.data(), 1, frame.data.size(), pipe_) != frame.data.size())
    return fail(ErrorKind::Device, "--video " + path_ + ": ffmpeg stopped taking frames (its message is above)");
  return ok_status();
}

Status VideoOutput::finish() {
  if (apng_) return apng_->finish();
  if (!pipe_) return fail(ErrorKind::BadUsage, "--video " + path_ + ": already finished");
  const int rc = pclose(pipe_);
  pipe_ = nullptr;
  std::error_code ec;
  if (rc != 0) {
    fs::remove(partial_, ec);
    return fail(ErrorKind::Device, "--video " + path_ + ": ffmpeg failed (exit status " + std::to_string(rc) + ")");
  }
  fs::rename(partial_, path_, ec);
  if (ec) return fail(ErrorKind::BadInput, "--video " + path_ + ": cannot rename " + partial_ + ": " + ec.message());
  return ok_status();
}

}  // namespace mrgi::tool
