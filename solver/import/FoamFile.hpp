#pragma once
/// \file FoamFile.hpp
/// One OpenFOAM data file read whole: the `FoamFile { ... }` header and a cursor over the body that
/// reads the tokens and lists rcfd imports (fields, mesh, Lagrangian clouds). rcfd parses the files
/// itself: VTK's OpenFOAM reader (Debian libvtk9-dev) cannot be installed beside python3-paraview,
/// which the project's ParaView check needs.
///
/// The format is OpenFOAM's (OpenFOAM User Guide, "Basic input/output file format", and the Ostream
/// sources): a list is `N ( item item ... )`, or `N{value}` for N equal items; in a file whose header
/// says `format binary;` a list of scalars, vectors or labels is `N (` followed by the raw
/// little-endian values and `)`. Labels are 32-bit unless the header's `arch` names `label=64`,
/// scalars 64-bit unless it names `scalar=32`. A file `NAME.gz` is read through zlib wherever `NAME` is
/// asked for and absent. Every malformed input throws rcfd::InputError naming the file, the entry and
/// the line, never anything else.

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace rcfd::openfoam {

class FoamFile {
 public:
  /// Reads `path`, or `path.gz` when `path` is absent; InputError naming the path when neither exists
  /// or the header is malformed.
  static FoamFile read(const std::filesystem::path& path);
  /// `path` or `path.gz`, whichever exists (path first); nullopt if neither.
  static std::optional<std::filesystem::path> locate(const std::filesystem::path& path);
  /// A file from bytes in memory (tests); `name` stands for the path in messages.
  static FoamFile fromText(std::string text, std::string name);

  const std::string& path() const { return path_; }
  bool binary() const { return binary_; }
  int labelBytes() const { return labelBytes_; }
  int scalarBytes() const { return scalarBytes_; }
  /// Header entry (`class`, `object`, `arch`, `note`, ...) without quotes; empty if absent.
  std::string header(const std::string& key) const;

  /// \name Cursor over the body (starts right after the header)
  ///@{
  /// Moves to the value of top-level keyword `keyword` (skipping other entries and their blocks);
  /// false if the body has no such entry.
  bool seekKeyword(const std::string& keyword);
  /// The next word or number token; InputError when the body ends or a punctuation character follows.
  std::string word(const std::string& what);
  double scalar(const std::string& what);
  std::int64_t label(const std::string& what);
  /// Consumes character `c` (after white space and comments), else InputError "expected 'c'".
  void expect(char c, const std::string& what);
  /// The next non-space character without consuming it (0 at the end).
  char peek();
  /// A list of scalars / vectors (3 per item, xyz) / labels in ASCII, `N{value}` or binary form.
  std::vector<double> scalarList(const std::string& what);
  std::vector<double> vectorList(const std::string& what);
  std::vector<std::int64_t> labelList(const std::string& what);
  /// A list of label lists (`faceList`: `N ( k(a b c ...) ... )`, ASCII only: binary files hold faces
  /// as faceCompactList, two labelLists). Offsets (n + 1) and the flat labels.
  void labelListList(const std::string& what, std::vector<std::int64_t>& offsets,
                     std::vector<std::int64_t>& labels);
  /// Raw bytes of a binary record `( bytes )` of exactly `count` bytes (a Lagrangian position).
  const char* rawRecord(std::size_t count, const std::string& what);
  ///@}

  /// InputError naming the file, `what` and the current line: "expected ..., got ...".
  [[noreturn]] void fail(const std::string& what, const std::string& message) const;
  /// 1-based line of the cursor (counting the text before it; binary payloads count their newlines).
  int line() const;

 private:
  FoamFile() = default;
  void parseHeader();
  void skipSpace();
  /// Reads one token: a word/number, or a single punctuation character; empty at the end.
  std::string token();
  void skipEntry();
  template <class T>
  std::vector<T> numericList(const std::string& what, int components, bool labels);

  std::string path_;
  std::string text_;
  std::size_t pos_ = 0;
  std::size_t bodyStart_ = 0;
  std::map<std::string, std::string> header_;
  bool binary_ = false;
  int labelBytes_ = 4;
  int scalarBytes_ = 8;
};

}  // namespace rcfd::openfoam
