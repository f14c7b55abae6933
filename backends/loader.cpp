/// The tables of backends/backends.h loaded from libsprig_backends.so on first use: the
/// `sprig` binary's provider, so that commands that read and write no image and build no
/// distance field never load OpenImageIO or OpenVDB.

#include <dlfcn.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <system_error>

#include "backends/backends.h"

namespace sprig {

namespace {

constexpr const char* kLibraryName = "libsprig_backends.so";

/// The library's tables, loaded once (thread-safe). Looks beside the running binary first,
/// then where the dynamic loader looks (LD_LIBRARY_PATH, the system's folders). Throws
/// std::runtime_error naming every place tried and the loader's message.
const backends::Backends& loaded() {
  static const backends::Backends* all = [] {
    std::string tried;
    void* lib = nullptr;
    std::error_code ec;
    const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (!ec) {
      const std::string beside = (self.parent_path() / kLibraryName).string();
      lib = dlopen(beside.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (!lib) tried += std::string("\n  ") + dlerror();
    }
    if (!lib) {
      lib = dlopen(kLibraryName, RTLD_NOW | RTLD_LOCAL);
      if (!lib) tried += std::string("\n  ") + dlerror();
    }
    if (!lib)
      throw std::runtime_error(std::string("cannot load ") + kLibraryName +
                               " (Sprig's OpenImageIO and OpenVDB code, built beside the sprig binary):" + tried);
    auto entry = reinterpret_cast<const backends::Backends* (*)()>(dlsym(lib, backends::kBackendsEntry));
    const backends::Backends* b = entry ? entry() : nullptr;
    if (!b || b->version != backends::kBackendsVersion)
      throw std::runtime_error(std::string(kLibraryName) + " is not the one this sprig binary was built with");
    return b;
  }();
  return *all;
}

}  // namespace

const detail::ImageBackend& detail::imageBackend() { return *loaded().image; }
const textures::detail::TextureBackend& textures::detail::textureBackend() { return *loaded().texture; }
const organisms::detail::VolumeBackend& organisms::detail::volumeBackend() { return *loaded().volume; }
const solids::detail::MeshDistanceBackend& solids::detail::meshDistanceBackend() { return *loaded().meshDistance; }

}  // namespace sprig
