#pragma once
/// Reading a .glb back in the model tests (TinyGLTF).

#include <catch2/catch.hpp>

#include <tiny_gltf.h>

#include <filesystem>
#include <string>

namespace sprig::test {

/// The glTF model in file; fails the test when TinyGLTF cannot read it.
inline tinygltf::Model readGlb(const std::filesystem::path& file) {
  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  const bool read = loader.LoadBinaryFromFile(&model, &err, &warn, file.string());
  INFO(file.string() << ": " << err);
  REQUIRE(read);
  return model;
}

}  // namespace sprig::test
