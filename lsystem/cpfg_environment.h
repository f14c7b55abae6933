#pragma once
/// cpfg's environmental programs (open L-systems, `cpfg -e FILE.e`): the environment file,
/// and the client that runs the program it names and exchanges `?E` modules with it.
///
/// The program is a separate process speaking vlab's plain-text protocol (docs/GRAMMAR.md,
/// "Environmental programs"): before every derivation step the turtle interprets the string,
/// and each `?E` module it reaches is sent as one item (its distance in cpfg's string, the
/// module and the one after it, the turtle's vectors in the file's printf formats); after a
/// `Control:` line the program answers `distance E(values)` for the modules it sets. The
/// transport is the one the file names (pipes, files or shared memory with a semaphore
/// pair), because the program reads the same file. Sprig never links vlab: it spawns the
/// program and talks to it.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace sprig::lsystem {

/// An environment file (`.e`), as cpfg's communication library reads it.
struct EnvironmentSpec {
  /// How the two processes exchange data (`communication type:`); the program reads the same
  /// line, so the client must use it too.
  enum class Transport { Pipes, Files, Memory };
  std::string file;                    ///< the file's path as given
  Transport transport = Transport::Pipes;
  /// Items per chunk for pipes and files (`communication type: pipes N`): 100 for pipes,
  /// 1000 for files by default; memory chunks are bounded by bytes (50,000) instead.
  int maxQueries = 100;
  /// `executable:` split on blanks (a trailing `&` dropped); the first word is the program.
  std::vector<std::string> command;
  /// printf formats of `turtle position:`, `turtle heading:`, `turtle left:`, `turtle up:`
  /// (each with 1 to 3 floating conversions); unset: not sent.
  std::optional<std::string> position, heading, left, up;
  bool followingModule = true;         ///< `following module: yes|no` (default yes)
};

/// Reads an environment file. Throws InputError (`FILE.e:line:col: error: ...`) for a file
/// that cannot be read, no `executable:`, an unknown directive, a format that is not 1-3
/// floating conversions, or a feature Sprig does not implement (`interpreted modules:` and
/// `when interpret:`, which send the turtle's geometry; `strings only:`, `binary data:`,
/// `remote host:`, sockets, `turtle line width:`, `turtle scale factor:`), each named.
EnvironmentSpec readEnvironmentFile(const std::string& path);

/// One `?E` module reached by the turtle, as cpfg sends it.
struct EnvironmentQuery {
  uint64_t distance = 0;                 ///< bytes from the first `?E` of the pass, in cpfg's string
  std::vector<float> params;             ///< the `?E` module's parameters
  std::string next;                      ///< cpfg's symbol of the following module ("" at the end)
  std::vector<float> nextParams;         ///< its parameters
  std::array<float, 3> position{}, heading{}, left{}, up{};  ///< cpfg's turtle (up: cpfg's U)
};

/// One answer: the `?E` module at `distance` gets the values that are set.
struct EnvironmentAnswer {
  uint64_t distance = 0;
  std::vector<std::optional<float>> params;
};

/// Limits of the client (docs/ROBUSTNESS.md).
struct EnvironmentOptions {
  /// Longest wait for the program to start or answer, in seconds.
  double timeoutSeconds = 60.0;
};

/// A running environmental program. Not thread-safe; not copyable. The destructor ends the
/// program (cpfg's exit message, then SIGKILL after 2 s) and reaps it, in every path.
///
/// Errors (InputError, `sprig: error: environmental program 'NAME' ...`): the program is
/// not found or not executable, fails its start (no handshake), exits, sends a malformed
/// line or an answer for a module it was not sent, or exceeds the timeout.
class EnvironmentProgram {
 public:
  /// Starts the program of spec in workDir (the object's folder, where cpfg runs it; the
  /// `.e` file is passed as `-e FILE` when the command does not give one).
  EnvironmentProgram(EnvironmentSpec spec, std::string workDir, EnvironmentOptions options = {});
  ~EnvironmentProgram();
  EnvironmentProgram(const EnvironmentProgram&) = delete;
  EnvironmentProgram& operator=(const EnvironmentProgram&) = delete;

  /// One interpretation pass's exchange: sends the queries (in chunks, as cpfg does) and the
  /// closing `Control:` line with `step` (steps done so far), and returns every answer.
  /// An empty pass sends nothing, as cpfg sends nothing when no `?E` is reached.
  std::vector<EnvironmentAnswer> exchange(const std::vector<EnvironmentQuery>& queries, int step);
  /// Ends the program and starts it again (a derivation that starts over from the axiom).
  void restart();
  /// The program's name for messages (the first word of `executable:`).
  const std::string& name() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The text of one query item as cpfg writes it (`12 E(0.5)F(1)\nP:1.0000 2.0000 0\n`).
std::string formatEnvironmentQuery(const EnvironmentSpec& spec, const EnvironmentQuery& q);

/// Parses an answer line (`12 E(0.3,,1)`); nullopt when it is malformed.
std::optional<EnvironmentAnswer> parseEnvironmentAnswer(const std::string& line);

}  // namespace sprig::lsystem
