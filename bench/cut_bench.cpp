// `drape bench cut`: whether a garment keeps its cut on a body that does not move. Every
// character (the default avatar and each shared one), skirt and dress, both models: the
// garment put on in the first pose of the character's chosen clip, the clip then held still
// for 5 s; the hem's mean radius (each warp line's last particle, horizontally from the
// centre of the fitting row) in the cut (the builder's rest shape), once put on, and after
// the 5 s. A flared garment hangs in folds, so its hem comes in from the cut in either
// model; what the figure asks is how far the simplified model, which has no bending
// springs, ends from the classic one, which has them: within 15 % (the issue "Any
// character, any motion", item 4). Measures only; it changes nothing in the solver.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "bench/characters.hpp"
#include "bench/report.hpp"
#include "drape/components/animation_player.hpp"
#include "drape/components/garment.hpp"
#include "drape/game/world.hpp"
#include "drape/systems/cloth/garment_quality.hpp"

namespace drape::bench {

namespace {

constexpr int still_frames = 300;     // 5 s at 1/60 s
constexpr double cut_share = 0.15;    // the simplified hem within this share of the classic one

struct Row {
    std::string character, garment, model;
    double cut_m = 0, put_on_m = 0, still_m = 0;
    bool finite = true;
};

}  // namespace

Result<void> run_cut(const BenchOptions& options) {
    std::vector<Row> rows;
    std::vector<std::string> not_run;
    for (const CharacterFile& c : character_files()) {
        for (const GarmentType type : {GarmentType::skirt, GarmentType::dress})
            for (const ClothModel model : {ClothModel::simplified, ClothModel::classic}) {
                Row row{c.name, garment_type_name(type), cloth_model_name(model)};
                if (!matches_filter(row.character + " " + row.garment + " " + row.model, options.filter)) continue;
                SceneDescription scene;
                scene.characters.emplace_back();
                scene.characters[0].file = c.file;
                scene.garments.emplace_back();
                scene.garments[0].type = type;
                scene.garments[0].model = model;
                for (const auto& [name, value] : options.garment_parameters) scene.garments[0].parameters.push_back({name, value});
                scene.solver.threads = options.threads;
                WorldOptions world_options;
                world_options.profile = false;
                auto world = build_world(scene, world_options);
                if (!world) {
                    if (type == GarmentType::skirt && model == ClothModel::simplified)
                        not_run.push_back(c.name + ": " + world.error().message);
                    continue;
                }
                world->registry.get<AnimationPlayer>(world->characters.at(0)).speed = 0;
                const Garment& g = world->registry.get<Garment>(world->garments.at(0));
                row.cut_m = hem_radius_m(*g.fabric, g.fabric->rest_shape, true);
                row.put_on_m = hem_radius_m(*g.fabric, g.state.x, false);
                for (int frame = 0; frame < still_frames; ++frame)
                    if (auto ok = step_world(*world, 1.0 / 60.0); !ok) return fail("cut: " + c.name + ": " + ok.error().message);
                row.finite = g.state.x.allFinite();
                row.still_m = hem_radius_m(*g.fabric, g.state.x, false);
                std::fprintf(stderr, "drape bench cut: %s %s %s: cut %.3f m, put on %.3f m, still %.3f m\n", row.character.c_str(),
                             row.garment.c_str(), row.model.c_str(), row.cut_m, row.put_on_m, row.still_m);
                rows.push_back(row);
            }
    }

    BenchOptions once = options;  // one run per case: the figures are lengths, not times
    once.runs = 1;
    Report report("A garment's cut on a still body", once, describe_machine());
    report.paragraph(
        "Each character's garment put on in the first pose of its chosen clip (a walk where it has one), the clip then held "
        "still for " + std::to_string(still_frames / 60) + " s, one thread, shipped settings" + changed_parameters(options) + ". The hem's radius: the mean "
        "horizontal distance of each warp line's last particle from the centre of the fitting row, in the cut (the "
        "builder's rest shape), once put on, and after the still seconds. A flared garment hangs in folds, so its hem comes "
        "in from the cut in either model; the figure is how far the simplified model (stretch springs only) ends from the "
        "classic one (with shear and bending springs): the target is within " + fixed(100 * cut_share, 0) + " %.");
    std::vector<std::vector<std::string>> table;
    std::vector<Target> targets;
    nlohmann::json json = nlohmann::json::array();
    int within = 0, pairs = 0;
    for (const Row& r : rows) {
        json.push_back({{"character", r.character}, {"garment", r.garment}, {"model", r.model}, {"cut_radius_m", r.cut_m},
                        {"put_on_radius_m", r.put_on_m}, {"still_radius_m", r.still_m}, {"finite", r.finite}});
        if (r.model != "simplified") continue;
        const Row* classic = nullptr;
        for (const Row& o : rows)
            if (o.character == r.character && o.garment == r.garment && o.model == "classic") classic = &o;
        std::string ratio = "-", ok = "-";
        if (classic && classic->still_m > 0) {
            const double q = r.still_m / classic->still_m;
            ratio = fixed(q, 2);
            const bool met = std::abs(q - 1) <= cut_share;
            ok = met ? "yes" : "no";
            within += met;
            ++pairs;
        }
        table.push_back({r.character, r.garment, fixed(100 * r.cut_m, 1), fixed(100 * r.put_on_m, 1),
                         fixed(100 * r.still_m, 1), classic ? fixed(100 * classic->put_on_m, 1) : "-",
                         classic ? fixed(100 * classic->still_m, 1) : "-", ratio, ok});
    }
    report.heading("Hem radius, cm");
    report.table({"character", "garment", "cut", "simplified put on", "simplified still", "classic put on", "classic still",
                  "simplified / classic", "within " + fixed(100 * cut_share, 0) + " %"},
                 table);
    report.paragraph(std::to_string(within) + " of " + std::to_string(pairs) + " garments keep the simplified hem within " +
                     fixed(100 * cut_share, 0) + " % of the classic one.");
    if (!not_run.empty()) {
        std::string text = "Not run: ";
        for (const std::string& n : not_run) text += n + "; ";
        report.paragraph(text);
    }
    return finish(report, once, {{"runs", json}, {"within", within}, {"pairs", pairs}});
}

}  // namespace drape::bench
