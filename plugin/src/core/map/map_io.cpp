#include "autograv/map/map_io.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "autograv/error.h"
#include "core/map/map_json.h"

namespace autograv {

namespace {

std::string systemError(int error_number) { return std::strerror(error_number); }

/// Removes the temporary file unless release() was called.
class TemporaryFileGuard {
 public:
  explicit TemporaryFileGuard(std::string path) : path_(std::move(path)) {}
  ~TemporaryFileGuard() {
    if (!path_.empty()) ::unlink(path_.c_str());
  }
  TemporaryFileGuard(const TemporaryFileGuard&) = delete;
  TemporaryFileGuard& operator=(const TemporaryFileGuard&) = delete;
  void release() { path_.clear(); }

 private:
  std::string path_;
};

/// Writes all of `text` to `fd`; on failure returns errno (0 on success).
int writeAll(int fd, const std::string& text) {
  const char* data = text.data();
  std::size_t left = text.size();
  while (left > 0) {
    const ssize_t written = ::write(fd, data, left);
    if (written < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    data += written;
    left -= static_cast<std::size_t>(written);
  }
  return 0;
}

std::string reasonFor(int error_number) {
  std::string reason = systemError(error_number);
  if (error_number == ENOSPC || error_number == EDQUOT) reason += " (the disk is full)";
  if (error_number == EROFS || error_number == EACCES || error_number == EPERM) {
    reason += " (is the folder writable?)";
  }
  return reason;
}

/// A device or a pipe (/dev/null, /dev/stdout, a FIFO) is written into: it cannot be replaced by
/// a rename, and must not be (renaming over /dev/full as root would swap the device node for a
/// plain file). Such a target holds no earlier file that could be damaged.
void writeIntoSpecialFile(const std::string& path, const std::string& text,
                          const std::string& what) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) {
    throw Error("saving " + what + " '" + path + "': cannot open: " + reasonFor(errno));
  }
  const int write_error = writeAll(fd, text);
  const int close_error = ::close(fd) != 0 ? errno : 0;
  if (write_error != 0 || close_error != 0) {
    throw Error("saving " + what + " '" + path +
                "': write failed: " + reasonFor(write_error != 0 ? write_error : close_error));
  }
}

/// How `path` is written: false for a regular file (or none yet), true for a device or a pipe.
/// Throws when `path` names a folder; `action` starts the message ("saving map").
bool isSpecialFile(const std::string& path, const std::string& action) {
  const std::filesystem::path target(path);
  struct stat existing {};
  if (target.filename().empty() ||
      (::stat(path.c_str(), &existing) == 0 && S_ISDIR(existing.st_mode))) {
    throw Error(action + " '" + path + "': the path names a folder, not a file");
  }
  return ::stat(path.c_str(), &existing) == 0 && !S_ISREG(existing.st_mode);
}

/// The folder `path` is in ("." for a bare name).
std::filesystem::path folderOf(const std::string& path) {
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  return folder.empty() ? std::filesystem::path(".") : folder;
}

/// Creates a unique hidden temporary file next to `path`; stores its name in `temporary_path`.
/// Throws "<action> '<path>': cannot create a temporary file in ...".
int createTemporaryBeside(const std::string& path, const std::string& action,
                          std::string& temporary_path) {
  const std::filesystem::path folder = folderOf(path);
  const std::string pattern =
      (folder / ("." + std::filesystem::path(path).filename().string() + ".tmp-XXXXXX")).string();
  std::vector<char> temporary(pattern.begin(), pattern.end());
  temporary.push_back('\0');
  const int fd = ::mkstemp(temporary.data());
  if (fd < 0) {
    throw Error(action + " '" + path + "': cannot create a temporary file in '" + folder.string() +
                "': " + reasonFor(errno) + "; the previous file, if any, is untouched");
  }
  temporary_path = temporary.data();
  return fd;
}

/// Follows the parser through the document, so that an error can name the field it was reading.
class ParsePosition {
 public:
  void onEvent(nlohmann::json::parse_event_t event, const nlohmann::json& parsed) {
    using Event = nlohmann::json::parse_event_t;
    switch (event) {
      case Event::object_start:
        frames_.push_back(Frame{false, 0, {}});
        break;
      case Event::array_start:
        frames_.push_back(Frame{true, 0, {}});
        break;
      case Event::key:
        if (!frames_.empty()) frames_.back().key = parsed.get<std::string>();
        break;
      case Event::object_end:
      case Event::array_end:
        if (!frames_.empty()) frames_.pop_back();
        elementDone();
        break;
      case Event::value:
        elementDone();
        break;
    }
  }

  /// JSON pointer of the value being read, e.g. "/grid/side_m"; "/" at the top level.
  std::string pointer() const {
    nlohmann::json::json_pointer pointer;
    for (const Frame& frame : frames_) {
      if (frame.array) {
        pointer /= frame.index;
      } else {
        pointer /= frame.key;
      }
    }
    const std::string text = pointer.to_string();
    return text.empty() ? "/" : text;
  }

 private:
  struct Frame {
    bool array;
    std::size_t index;  // of the element being read, in an array
    std::string key;    // of the member being read, in an object
  };

  void elementDone() {
    if (!frames_.empty() && frames_.back().array) ++frames_.back().index;
  }

  std::vector<Frame> frames_;
};

/// Parses `text` as JSON. Every failure, a syntax error or a number beyond the range of double
/// alike, becomes an autograv::Error naming `source` and the field being read.
nlohmann::json parseJsonDocument(const std::string& text, const std::string& source) {
  ParsePosition position;
  const auto follow = [&position](int /*depth*/, nlohmann::json::parse_event_t event,
                                  nlohmann::json& parsed) {
    position.onEvent(event, parsed);
    return true;
  };
  try {
    return nlohmann::json::parse(text, follow);
  } catch (const nlohmann::json::parse_error& error) {
    throw Error("map file '" + source + "': not valid JSON (truncated or corrupted?) in field " +
                position.pointer() + ": " + error.what());
  } catch (const nlohmann::json::out_of_range& error) {
    throw Error("map file '" + source + "': field " + position.pointer() +
                ": a number beyond the range of double (about 1.8e308): " + error.what());
  } catch (const nlohmann::json::exception& error) {
    throw Error("map file '" + source + "': cannot read field " + position.pointer() + ": " +
                error.what());
  }
}

}  // namespace

void checkWritable(const std::string& path, const std::string& what) {
  const std::string action = "cannot write " + what;
  if (isSpecialFile(path, action)) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd < 0) throw Error(action + " '" + path + "': cannot open: " + reasonFor(errno));
    ::close(fd);
    return;
  }
  std::string temporary_path;
  const int fd = createTemporaryBeside(path, action, temporary_path);
  const TemporaryFileGuard guard(temporary_path);
  // One byte takes a block: a full disk says so now.
  const int write_error = writeAll(fd, "?");
  ::close(fd);
  if (write_error != 0) {
    throw Error(action + " '" + path + "': a test write failed: " + reasonFor(write_error) +
                "; the previous file, if any, is untouched");
  }
}

void writeFileAtomically(const std::string& path, const std::string& text,
                         const std::string& what) {
  const std::string action = "saving " + what;
  if (isSpecialFile(path, action)) {
    writeIntoSpecialFile(path, text, what);
    return;
  }
  std::string temporary_path;
  const int fd = createTemporaryBeside(path, action, temporary_path);
  TemporaryFileGuard guard(temporary_path);
  // mkstemp creates 0600; these files are not secret: readable like any other file.
  ::fchmod(fd, 0644);
  const auto fail = [&](const char* step, int error_number) {
    ::close(fd);
    throw Error("saving " + what + " '" + path + "': " + step + " failed: " +
                reasonFor(error_number) + "; the previous file, if any, is untouched");
  };
  if (const int error_number = writeAll(fd, text); error_number != 0) fail("write", error_number);
  if (::fsync(fd) != 0) fail("fsync", errno);
  if (::close(fd) != 0) {
    throw Error("saving " + what + " '" + path + "': close failed: " + reasonFor(errno) +
                "; the previous file, if any, is untouched");
  }
  if (::rename(temporary_path.c_str(), path.c_str()) != 0) {
    throw Error("saving " + what + " '" + path +
                "': cannot rename the temporary file into place: " + reasonFor(errno) +
                "; the previous file, if any, is untouched");
  }
  guard.release();
  // Best effort: some file systems refuse fsync on a folder; the data itself is already safe.
  const int folder_fd = ::open(folderOf(path).c_str(), O_RDONLY | O_DIRECTORY);
  if (folder_fd >= 0) {
    ::fsync(folder_fd);
    ::close(folder_fd);
  }
}

std::uint64_t fnv1a64(const std::string& bytes) noexcept {
  std::uint64_t hash = 0xcbf29ce484222325ULL;
  for (const char c : bytes) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 0x100000001b3ULL;
  }
  return hash;
}

std::string mapToJson(const GravityMap& map) { return detail::mapToDocument(map).dump(2) + "\n"; }

GravityMap mapFromJson(const std::string& text, const std::string& source,
                       const MapLoadOptions& options) {
  return detail::mapFromDocument(parseJsonDocument(text, source), source, options);
}

GravityMap loadMap(const std::string& path, const MapLoadOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw Error("map file '" + path + "': cannot open: " + systemError(errno) +
                " (a calibration with WizardConfig::map_path set to this path makes one)");
  }
  std::ostringstream content;
  content << in.rdbuf();
  if (in.bad()) throw Error("map file '" + path + "': read error: " + systemError(errno));
  return mapFromJson(content.str(), path, options);
}

void saveMap(const GravityMap& map, const std::string& path) {
  writeFileAtomically(path, mapToJson(map), "map");
}

}  // namespace autograv
