#include "mrgi/platform/output_dir.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace mrgi {
namespace fs = std::filesystem;

namespace {

std::string normalised(const std::string& dir) {
  std::string d = fs::absolute(fs::path(dir)).lexically_normal().string();
  while (d.size() > 1 && d.back() == '/') d.pop_back();
  return d;
}

// Whether `ancestor` is `path` or one of its parents (both absolute and normalised).
bool is_same_or_parent(const std::string& ancestor, const std::string& path) {
  if (ancestor == path) return true;
  const std::string prefix = ancestor == "/" ? "/" : ancestor + "/";
  return path.compare(0, prefix.size(), prefix) == 0;
}

// Refusal message for an existing path that is not ours, or "" when it may be replaced.
std::string why_not_replaceable(const std::string& path, const std::string& what) {
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(path, ec);
  if (ec || !fs::exists(st)) return "";
  if (fs::is_symlink(st))
    return path + ": " + what + " is a symbolic link; refusing to replace it (choose a folder path)";
  if (!fs::is_directory(st))
    return path + ": " + what + " exists and is not a folder; refusing to replace it";
  if (!is_replaceable_output(path))
    return path + ": " + what + " exists and was not written by mrgi (no " + OutputDir::kMarker +
           " marker in it); refusing to replace or delete it: choose another folder, or remove it "
           "yourself";
  return "";
}

}  // namespace

bool is_replaceable_output(const std::string& path) {
  std::error_code ec;
  if (!fs::is_directory(fs::symlink_status(path, ec))) return false;
  if (fs::is_empty(path, ec) && !ec) return true;
  return fs::is_regular_file(fs::symlink_status(fs::path(path) / OutputDir::kMarker, ec));
}

Expected<OutputDir> OutputDir::begin(const std::string& dir_in, const std::string& option) {
  if (dir_in.empty()) return fail(ErrorKind::BadUsage, option + ": the output folder must not be empty");
  if (dir_in.find('\0') != std::string::npos)
    return fail(ErrorKind::BadUsage, option + ": the output folder name holds a NUL byte");
  const std::string dir = normalised(dir_in);
  std::error_code ec;
  const std::string cwd = normalised(fs::current_path(ec).string());
  if (dir == "/" || fs::path(dir).parent_path().empty())
    return fail(ErrorKind::BadUsage, option + " " + dir + ": refusing the file-system root as an output folder");
  if (!ec && is_same_or_parent(dir, cwd))
    return fail(ErrorKind::BadUsage, option + " " + dir + ": refusing the current folder or one of its parents "
                                                          "as an output folder (it would be replaced)");
  if (const char* home = std::getenv("HOME"); home && *home && is_same_or_parent(dir, normalised(home)))
    return fail(ErrorKind::BadUsage, option + " " + dir + ": refusing the home folder or one of its parents "
                                                          "as an output folder");
  OutputDir out;
  out.dir_ = dir;
  out.partial_ = dir + ".partial";
  out.option_ = option;
  if (std::string why = why_not_replaceable(dir, option); !why.empty()) return fail(ErrorKind::BadUsage, why);
  if (std::string why = why_not_replaceable(out.partial_, option + "'s unfinished output"); !why.empty())
    return fail(ErrorKind::BadUsage, why);
  fs::remove_all(out.partial_, ec);  // an earlier run's, marked: ours
  ec.clear();
  fs::create_directories(out.partial_, ec);
  if (ec) return fail(ErrorKind::BadInput, out.partial_ + ": cannot create the output folder: " + ec.message());
  {
    std::ofstream marker(fs::path(out.partial_) / kMarker);
    marker << "Written by mrgi: this folder is its output, which a later run may replace.\n";
    if (!marker) {
      fs::remove_all(out.partial_, ec);
      return fail(ErrorKind::BadInput, out.partial_ + ": cannot write the output marker");
    }
  }
  out.active_ = true;
  return out;
}

OutputDir::OutputDir(OutputDir&& o) noexcept
    : dir_(std::move(o.dir_)), partial_(std::move(o.partial_)), option_(std::move(o.option_)), active_(o.active_) {
  o.active_ = false;
}

OutputDir& OutputDir::operator=(OutputDir&& o) noexcept {
  if (this != &o) {
    abandon();
    dir_ = std::move(o.dir_);
    partial_ = std::move(o.partial_);
    option_ = std::move(o.option_);
    active_ = o.active_;
    o.active_ = false;
  }
  return *this;
}

OutputDir::~OutputDir() { abandon(); }

void OutputDir::abandon() {
  if (!active_) return;
  active_ = false;
  std::error_code ec;
  if (is_replaceable_output(partial_)) fs::remove_all(partial_, ec);
}

Status OutputDir::commit() {
  if (!active_) return fail(ErrorKind::BadUsage, option_ + ": commit() on an output folder that is not open");
  // Checked again: the folder may have changed while the run went on.
  if (std::string why = why_not_replaceable(dir_, option_); !why.empty()) return fail(ErrorKind::BadUsage, why);
  std::error_code ec;
  fs::remove_all(dir_, ec);
  ec.clear();
  fs::rename(partial_, dir_, ec);
  if (ec) return fail(ErrorKind::Device, dir_ + ": cannot move the finished output into place: " + ec.message());
  active_ = false;
  return ok_status();
}

}  // namespace mrgi
