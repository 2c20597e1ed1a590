// Round trips of the case format: `fretbuzz export` writes a built-in case with its data
// files, and the exported copy runs bit for bit like the built-in; `fretbuzz modes` output
// reads back as a [modes] table giving the very same modes and motion.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "TestSupport.hpp"
#include "fretbuzz/input/BuiltinFiles.hpp"
#include "fretbuzz/input/CaseExport.hpp"
#include "fretbuzz/output/CaseExportFolder.hpp"
#include "fretbuzz/run/Simulation.hpp"

namespace fretbuzz {
namespace {

namespace fs = std::filesystem;
using testing::run_cli;
using testing::ScratchDir;

std::string read_file(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

struct Motion : RunObserver {
    std::vector<double> u, h, f;
    void observation(double, std::span<const double> values) override { u.insert(u.end(), values.begin(), values.end()); }
    void energy(double, double e, double, double) override { h.push_back(e); }
    void bridge_force(double, double force) override { f.push_back(force); }
};

Motion short_run(Case c, double duration) {
    c.run.duration_s = duration;
    // Profile times beyond a run are refused: keep the points inside the shortened run, the
    // same cut for both cases compared (what is compared is the export, not the gesture).
    const auto cut = [duration](std::vector<std::array<double, 2>>& profile) {
        std::erase_if(profile, [duration](const std::array<double, 2>& p) { return p[0] > duration; });
    };
    for (FingerSpec& f : c.fingers) cut(f.force_profile);
    for (ForceSpec& f : c.forces) cut(f.force_profile);
    for (PluckSpec& p : c.plucks) p.start_s = std::min(p.start_s, duration);
    Motion m;
    RunObserver* observers[] = {&m};
    simulate(c, observers);
    return m;
}

void expect_same_motion(const Motion& a, const Motion& b, const std::string& what) {
    ASSERT_FALSE(a.u.empty()) << what;
    EXPECT_EQ(a.u, b.u) << what;
    EXPECT_EQ(a.h, b.h) << what;
    EXPECT_EQ(a.f, b.f) << what;
}

TEST(CaseExport, ExportedCasesRunBitForBitLikeTheBuiltinOnes) {
    ScratchDir dir("export");
    for (const auto& info : builtin_cases()) {
        const fs::path where = dir.path() / info.name;
        const std::vector<fs::path> written = export_builtin_case(info.name, where);
        ASSERT_FALSE(written.empty());
        EXPECT_EQ(read_file(written.front()), builtin_case_text(info.name)) << info.name;
        // Every file the case names is there, byte for byte (so the copy does not lean on
        // the built-in data, which a moved case would still find).
        for (std::size_t k = 1; k < written.size(); ++k) {
            const std::string relative = fs::relative(written[k], where).generic_string();
            ASSERT_TRUE(find_builtin_file(relative)) << relative;
            EXPECT_EQ(read_file(written[k]), std::string(*find_builtin_file(relative))) << relative;
            EXPECT_NE(builtin_case_text(info.name).find("\"" + relative + "\""), std::string::npos) << relative;
        }
        const Case builtin = load_case(info.name);
        const Case exported = load_case(written.front().string());
        EXPECT_EQ(exported.modes.frequency_hz, builtin.modes.frequency_hz) << info.name;
        EXPECT_EQ(exported.modes.sigma_per_s, builtin.modes.sigma_per_s) << info.name;
        EXPECT_EQ(exported.obstacle_height_m, builtin.obstacle_height_m) << info.name;
        EXPECT_EQ(exported.initial_displacement, builtin.initial_displacement) << info.name;
        expect_same_motion(short_run(builtin, 0.002), short_run(exported, 0.002), info.name);
    }
    // bass-pop names its mode table, fret profile and initial state.
    EXPECT_TRUE(fs::exists(dir.path() / "bass-pop" / "data" / "bass_fretted_obstacle.csv"));
    EXPECT_TRUE(fs::exists(dir.path() / "bass-pop" / "data" / "bass_fretted_modes.csv"));
    EXPECT_TRUE(fs::exists(dir.path() / "bass-pop" / "data" / "bass_fretted_initial_modal.csv"));
}

TEST(CaseExport, CommandWritesTheFilesAndTheCopyRunsIdentically) {
    ScratchDir dir("export-cli");
    const fs::path copy = dir.path() / "copy";
    auto r = run_cli("export bass-pop " + copy.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("bass-pop.toml"), std::string::npos) << r.output;
    const std::string options = " --duration 0.003 --output-rate native -q --out ";
    ASSERT_EQ(run_cli("run bass-pop" + options + (dir.path() / "a").string()).exit_code, 0);
    r = run_cli("run " + (copy / "bass-pop.toml").string() + options + (dir.path() / "b").string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    for (const char* file : {"observation.csv", "energy.csv", "bridge_force.csv"})
        EXPECT_EQ(read_file(dir.path() / "a" / file), read_file(dir.path() / "b" / file)) << file;

    const fs::path nowhere = dir.path() / "nowhere";
    r = run_cli("export no-such-case " + nowhere.string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("bass-pop"), std::string::npos) << r.output;  // the valid names
    EXPECT_FALSE(fs::exists(nowhere));
}

TEST(CaseExport, ModesOutputReadsBackAsAModeTable) {
    // The sitar's modes come from models; written by `fretbuzz modes` (17 digits, with the
    // source column) and read back as table = "...", they are the same numbers.
    ScratchDir dir("modes-trip");
    const auto r = run_cli("modes sitar");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    std::ofstream(dir.path() / "modes.csv") << r.output;
    std::string text = builtin_case_text("sitar");
    const std::size_t from = text.find("[modes.frequency]"), to = text.find("[obstacle]");
    ASSERT_NE(from, std::string::npos);
    text.replace(from, to - from, "[modes]\ntable = \"modes.csv\"\n\n");
    std::ofstream(dir.path() / "sitar-table.toml") << text;

    const Case models = load_case("sitar");
    const Case table = load_case((dir.path() / "sitar-table.toml").string());
    EXPECT_EQ(table.modes.frequency_hz, models.modes.frequency_hz);
    EXPECT_EQ(table.modes.sigma_per_s, models.modes.sigma_per_s);
    ASSERT_EQ(table.modes.source.size(), models.modes.source.size());
    EXPECT_EQ(table.modes.source.front(), ModeSource::model);
    expect_same_motion(short_run(models, 0.004), short_run(table, 0.004), "sitar");
}

}  // namespace
}  // namespace fretbuzz
