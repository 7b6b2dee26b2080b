// The one table of the common options (docs/design.md section 6): each knob's flag, ini key, help,
// range, enum names, the schemes it applies to and where it reaches in the viewer. The command
// line (options.cpp), the viewer's Parameters panel, its ini handler and the command-line-over-
// ini merge all walk it, so an option cannot be lost on the way to one of them.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "engine/accel/build_params.h"
#include "engine/render/tracer.h"
#include "engine/scene/scene.h"

namespace lancer::cli {

/// Every value the table describes. The command line fills one per subcommand; the viewer keeps
/// one in its settings (saved in its ini file).
struct Knobs {
    /// The command line's default scheme is the fastest one measured (docs/benchmarks.md);
    /// BuildParams itself defaults to brute force, the reference.
    BuildParams build = [] {
        BuildParams b;
        b.scheme = SchemeKind::Regular;
        return b;
    }();
    ShadingOptions shading;  ///< bounces, shadows, reflections, refractions, offset
    int threads = 0;         ///< render threads (0: all cores)
    /// Image size; 0: the scene's own (the other follows its aspect). The viewer's image viewport
    /// (the window opens around it with the panels).
    int width = 0, height = 0;
    ReadOptions read;        ///< --facets: how .csg files' round shapes are read
    std::string cameraPath;  ///< --camera: a .camera.json replacing the scene's camera
    std::string statsPath;   ///< --stats: statistics as JSON
    std::string depthPath;   ///< --depth: primary hit distances as PFM
};

/// What a knob's value is.
enum class ParamKind : uint8_t {
    Int,     ///< an integer in [lo, hi]
    Real,    ///< a number in [lo, hi]
    Enum,    ///< one of `names`, stored as its index
    Switch,  ///< on or off; the flag sets `flagValue`
    Size,    ///< bytes, written 512M, 2G, 1.5GiB (parseMemoryBudget); 0: the default
    Path,    ///< a file name (Knobs' `path` member)
};

/// Where a knob reaches in the viewer.
enum class ViewerReach : uint8_t {
    Panel,      ///< a control in the Parameters panel and an ini key
    Window,     ///< the window's size: an ini key, changed by resizing the window
    Startup,    ///< read once at start (a file); its live control is another panel's
    BatchOnly,  ///< render, trace and structure only: the viewer has no use for it
};

/// What a change of a knob asks of the viewer.
enum class ChangeEffect : uint8_t { None, Rerender, Rebuild };

/// One scheme's bit in ParamDesc::schemes.
constexpr uint8_t schemeBit(SchemeKind k) { return uint8_t(1u << unsigned(k)); }
inline constexpr uint8_t kAllSchemes = (1u << kSchemeCount) - 1;

struct ParamDesc {
    const char* flag;     ///< "--max-level"
    const char* metavar;  ///< "N" in the help ("" for a switch)
    const char* iniKey;   ///< key in the viewer's ini; nullptr for Startup and BatchOnly
    const char* label;    ///< the panel control's label
    const char* help;     ///< one line: what it does
    ParamKind kind;
    double lo = 0.0, hi = 0.0;         ///< Int and Real: the accepted range, everywhere
    std::vector<const char*> names{};  ///< Enum: the names, index = the enum's value
    bool flagValue = true;             ///< Switch: the value the flag sets (false: --no-...)
    uint8_t schemes = kAllSchemes;     ///< the schemes that read it
    ViewerReach reach = ViewerReach::Panel;
    ChangeEffect effect = ChangeEffect::None;  ///< when it changes and applies
    /// Int, Real, Enum (index), Switch (0 or 1): the value in `k`, and setting it.
    double (*get)(const Knobs& k) = nullptr;
    void (*set)(Knobs& k, double v) = nullptr;
    std::string Knobs::*path = nullptr;  ///< Path: the member it fills
    /// Besides the scheme, when it is read (delta: with --step push only); nullptr: always.
    bool (*when)(const Knobs& k) = nullptr;
    /// Int: a word for the automatic value `autoValue` (lo - 1), taken and written in its
    /// place ("auto"); nullptr: none.
    const char* autoWord = nullptr;
    double autoValue = 0.0;
};

/// The table, in the order of the help.
std::span<const ParamDesc> paramTable();
/// The entry of `flag` ("--max-level"), or nullptr.
const ParamDesc* findParam(const std::string& flag);

/// Whether `d` is read under `k`'s scheme and settings (a panel greys out what is not).
bool applies(const ParamDesc& d, const Knobs& k);
/// What going from `before` to `after` asks of the viewer: a rebuild when a knob that
/// rebuilds changed and applies to `after`'s scheme (the scheme itself always applies), else a
/// re-render when a rendering knob changed, else nothing.
ChangeEffect changeEffect(const Knobs& before, const Knobs& after);

/// The value as the ini and the help write it: "24", "auto", "1e-06", "exact", "1" / "0", a
/// path.
std::string formatValue(const ParamDesc& d, const Knobs& k);
/// Parse `text` (the ini's form, or an enum name) into `k`. False, and `k` unchanged, when it
/// is not a value of `d` or lies outside its range.
bool parseValue(const ParamDesc& d, const std::string& text, Knobs& k);
/// Copy `d`'s value from `from` to `to`.
void copyValue(const ParamDesc& d, const Knobs& from, Knobs& to);

/// Apply a comma list of assignments NAME=VALUE (NAME an option's flag without its dashes or its
/// ini key, VALUE as the ini writes it or an enum name: "max-level=16,step=push,mailboxes=0";
/// a switch's value is its knob's, 1 on) to `k`, for the knobs
/// the viewer's Parameters panel changes. Throws std::invalid_argument naming the item that is
/// not one; `k` is then unchanged.
void applyAssignments(const std::string& list, Knobs& k);

/// The options section of README.md (between `<!-- options:begin -->` and
/// `<!-- options:end -->`), generated from the table: `lancer help-options` prints it and a test
/// checks README against it.
std::string optionsMarkdown();

}  // namespace lancer::cli
