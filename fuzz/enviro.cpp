/// Fuzz target: the two readers of cpfg's environmental programs (lsystem/cpfg_environment.h)
/// on any bytes. The first byte picks the reader:
/// - 0: the environment file (`.e`, readEnvironmentFile), written as fuzz.e into a fresh
///   sandbox folder; a file it reads is then given to formatEnvironmentQuery with a query
///   of the input's length in parameters, as the turtle would send it;
/// - 1: a program's answers, one parseEnvironmentAnswer per line (as the client reads a
///   chunk), then every parsed value is read back.
/// No program is ever started: the client's process and transport are tested in
/// tests/lsystem with real programs.
#include "fuzz/fuzz.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/diagnostics.h"
#include "lsystem/cpfg_environment.h"

namespace {

void fuzzEnvironmentFile(std::string_view body, size_t size) {
  const std::string path = sprig::fuzz::sandboxFolder("enviro") + "/fuzz.e";
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(body.data(), static_cast<std::streamsize>(body.size()));
  }
  try {
    const sprig::lsystem::EnvironmentSpec spec = sprig::lsystem::readEnvironmentFile(path);
    sprig::lsystem::EnvironmentQuery q;
    q.distance = size;
    q.params.assign(size % 5, 0.5f);
    if (size % 2) q.next.assign(1, 'F');  // (GCC 12 warns, falsely, on assigning a literal here)
    q.nextParams.assign(size % 3, 1.25f);
    q.position = {1.0f, -2.0f, 3.5f};
    volatile size_t n = sprig::lsystem::formatEnvironmentQuery(spec, q).size();
    (void)n;
  } catch (const sprig::InputError&) {
  }
}

void fuzzAnswers(std::string_view body) {
  size_t b = 0;
  while (b <= body.size()) {
    size_t e = body.find('\n', b);
    if (e == std::string_view::npos) e = body.size();
    const std::optional<sprig::lsystem::EnvironmentAnswer> a =
        sprig::lsystem::parseEnvironmentAnswer(std::string(body.substr(b, e - b)));
    if (a) {
      volatile float sum = static_cast<float>(a->distance);
      for (const std::optional<float>& v : a->params) sum = sum + (v ? *v : 0.0f);
    }
    b = e + 1;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0 || size > sprig::fuzz::kMaxInput) return 0;
  const std::string_view body = sprig::fuzz::text(data + 1, size - 1);
  if (data[0] % 2 == 0)
    fuzzEnvironmentFile(body, size);
  else
    fuzzAnswers(body);
  return 0;
}
