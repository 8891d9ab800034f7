// Output files of the command-line apps: checked before any work (a bad path should fail
// in milliseconds, not after a minute of loading and rendering) and written whole or not at
// all (a temporary beside each output, renamed when every output of the run is complete).
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace open3d {
namespace t {
namespace io {

/// Throws naming `what` (e.g. "--depth-output") and `path` unless `path` can be created:
/// not empty, not a folder, and its folder exists and is writable.
void CheckOutputPath(const std::string& what, const std::string& path);

/// Lower-case extension of a path without the dot ("png" for "a/B.PNG"; "" for none).
std::string LowerCaseExtension(const std::string& path);

/// True when `a` and `b` name the same file (compared after making both absolute and
/// resolving the parts that exist, so "x.png" and "./x.png" are the same).
bool SameOutputPath(const std::string& a, const std::string& b);

/// A file a tool reads, by the flag that names it (e.g. {"--input", "scene.ply"}).
struct NamedInput {
    std::string flag;
    std::string path;
};

/// Throws naming both flags and the path when `output` is one of `inputs` (the same file:
/// the same path after resolving links, or a hard link to it; empty paths are skipped). A
/// tool calls it for every output before any work, so no input is ever overwritten.
void CheckOutputIsNotAnInput(const std::string& what, const std::string& output,
                             const std::vector<NamedInput>& inputs);

/// A set of outputs written through temporaries: Add gives the path to write each output
/// to (in the output's folder, so the final rename does not cross file systems), Commit
/// renames them all once every one is written. Without Commit (an exception on the way)
/// the destructor removes the temporaries: no partial file and no partial set is left.
class OutputFileSet {
public:
    OutputFileSet() = default;
    ~OutputFileSet();
    OutputFileSet(const OutputFileSet&) = delete;
    OutputFileSet& operator=(const OutputFileSet&) = delete;

    /// Reserves a fresh temporary beside `final_path` and returns it. Its name ends with
    /// the final file name, so writers that pick the format by extension still do.
    std::string Add(const std::string& final_path);
    /// Add, then `write(temporary)`: an Open3DError it throws is thrown again with the
    /// temporary's name replaced by `final_path`, so messages name the user's file, and
    /// the temporary is removed from the set (a later Commit does not publish it).
    void Write(const std::string& final_path,
               const std::function<void(const std::string& temporary)>& write);
    /// Renames every temporary to its final path (replacing existing files).
    void Commit();

private:
    std::vector<std::pair<std::string, std::string>> files_;  // (temporary, final)
};

}  // namespace io
}  // namespace t
}  // namespace open3d
