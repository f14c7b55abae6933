#pragma once
/// The process and transport under lsystem::EnvironmentProgram: spawns the environmental
/// program, moves chunks of text to it and its answers back over the transport the
/// environment file names (pipes; files or shared memory with a pair of SysV semaphores, as
/// vlab's communication library expects), with a timeout on every wait, and ends and reaps
/// the program in every path. Private to lsystem/.

#include <memory>
#include <string>

#include "lsystem/cpfg_environment.h"

namespace sprig::lsystem::detail {

/// Flags of a `Control:` line (vlab's communication.h values).
inline constexpr int kFirstChunk = 1;
inline constexpr int kLastChunk = 4;
inline constexpr int kProcessExit = 8;

/// One running program and its transport. Not copyable; the destructor ends the program.
class EnviroChannel {
 public:
  /// Spawns spec's program in workDir and waits for its start signal (a byte 1 on the pipe,
  /// or the semaphore it clears). Throws InputError naming the program on any failure.
  static std::unique_ptr<EnviroChannel> start(const EnvironmentSpec& spec, const std::string& workDir,
                                              double timeoutSeconds);
  ~EnviroChannel();
  EnviroChannel(const EnviroChannel&) = delete;
  EnviroChannel& operator=(const EnviroChannel&) = delete;

  /// Starts a chunk of queries (empty).
  void beginChunk();
  /// Whether item still fits the chunk (items per chunk for pipes and files, bytes for memory).
  bool fits(const std::string& item) const;
  /// Adds item to the chunk.
  void append(const std::string& item);
  /// Ends the chunk with `Control: flag step`, hands it to the program and lets it run.
  void endChunk(int flag, int step);
  /// The program's next answer line; false at its `Control:` line that ends the answers
  /// (a chunk of answers without the last-chunk flag lets the program write the next one).
  bool readAnswer(std::string& line);
  /// Throws InputError `environmental program 'NAME' (FILE.e) <what>`, after which the
  /// destructor kills the program at once.
  [[noreturn]] void fail(const std::string& what);

 private:
  EnviroChannel() = default;
  struct State;
  std::unique_ptr<State> s_;
};

}  // namespace sprig::lsystem::detail
