/*
 * Motion and animation through hairtrace.hpp: strands and a mesh at several time steps, a
 * USD stage and a .hair sequence read at a frame over an open shutter. Each scene is
 * rendered once made through the C++ wrappers and once through the C calls they wrap;
 * the program prints whether the two images are the same bits, then what a bad time step
 * throws. Arguments: the animated USD stage, and a .hair sequence's pattern whose frames 1
 * and 2 exist.
 */
#include <hairtrace.hpp>

#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <vector>

namespace {

const uint32_t W = 32, H = 24;
const float SKY[3] = {0.5f, 0.5f, 0.6f};

/* 100 linear strands of 4 float4 control points on a 10 x 10 grid, moved dx along x. */
std::vector<float> grid(float dx) {
    std::vector<float> points;
    for (int s = 0; s < 100; ++s) {
        float x = static_cast<float>(s % 10) * 0.2f - 1.0f + dx;
        float z = static_cast<float>(s / 10) * 0.2f - 1.0f;
        for (int k = 0; k < 4; ++k) {
            float p[4] = {x + 0.05f * static_cast<float>(k), static_cast<float>(k) * 0.4f - 0.6f, z,
                          0.02f};
            points.insert(points.end(), p, p + 4);
        }
    }
    return points;
}

/* A strip of 8 quads along x, its vertices lifted along z by bend times their x. */
std::vector<float> strip(float bend) {
    std::vector<float> positions;
    for (int i = 0; i <= 8; ++i) {
        float x = static_cast<float>(i) * 0.25f - 1.0f;
        float v[6] = {x, -0.5f, bend * x, x, 0.5f, bend * x};
        positions.insert(positions.end(), v, v + 6);
    }
    return positions;
}

std::vector<uint32_t> strip_indices() {
    std::vector<uint32_t> indices;
    for (uint32_t i = 0; i < 8; ++i) {
        uint32_t t[6] = {2 * i, 2 * i + 2, 2 * i + 1, 2 * i + 1, 2 * i + 2, 2 * i + 3};
        indices.insert(indices.end(), t, t + 6);
    }
    return indices;
}

hairtrace::Settings blurred() {
    hairtrace::Settings settings;
    settings.set("width", std::to_string(W)).set("height", std::to_string(H));
    settings.set("spp", "2").set("threads", "2");
    settings.set("shutter_open", "-0.5").set("shutter_close", "0.5");
    return settings;
}

/* A new scene with a hair material (id 0) and a grey one (id 1), filled by `fill` under
 * the sky, rendered with `settings`. */
std::vector<float> render(const hairtrace::Device &device, const hairtrace::Settings &settings,
                          const std::function<void(hairtrace::Scene &)> &fill) {
    hairtrace::Scene scene(device);
    uint32_t hair = 0, grey = 0;
    HtHairParams params = ht_hair_params_default();
    const float albedo[3] = {0.6f, 0.5f, 0.4f};
    hairtrace::check(ht_scene_add_hair_material(scene.get(), &params, &hair));
    hairtrace::check(ht_scene_add_diffuse_material(scene.get(), albedo, &grey));
    fill(scene);
    hairtrace::check(ht_scene_add_environment(scene.get(), SKY));
    std::vector<float> rgb(W * H * 3);
    hairtrace::check(ht_render_with(scene.get(), settings.get(), nullptr, nullptr, rgb.data(),
                                    rgb.size(), nullptr, nullptr, nullptr, W * H));
    return rgb;
}

void same(const char *what, const std::vector<float> &a, const std::vector<float> &b) {
    bool equal = a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * 4) == 0;
    std::printf("same %s %d\n", what, equal ? 1 : 0);
}

} // namespace

int main(int argc, char **argv) {
    if (argc < 3) {
        std::fprintf(stderr, "usage: motion STAGE.usda GROOM.####.hair\n");
        return 2;
    }
    const std::string usd = argv[1], sequence = argv[2];
    hairtrace::Device device(2);
    hairtrace::Settings settings = blurred();

    std::vector<float> first = grid(0.0f), second = grid(0.1f), third = grid(0.3f);
    std::vector<uint32_t> counts(100, 4);
    HtCurvesXyzr desc;
    desc.strand_count = counts.size();
    desc.point_counts = counts.data();
    desc.point_count = first.size() / 4;
    desc.points = first.data();
    desc.colors = nullptr;
    desc.basis = HT_CURVE_LINEAR;
    desc.shape = HT_CURVE_ROUND;
    std::vector<const float *> later = {second.data(), third.data()};
    same("curves",
         render(device, settings,
                [&](hairtrace::Scene &s) { s.add_curves_xyzr_motion(desc, later, 0); }),
         render(device, settings, [&](hairtrace::Scene &s) {
             uint32_t id = 0;
             hairtrace::check(ht_scene_add_curves_xyzr_motion(s.get(), &desc, later.data(),
                                                              later.size(), 0, &id));
         }));

    std::vector<float> flat = strip(0.0f), bent = strip(1.0f);
    std::vector<uint32_t> indices = strip_indices();
    std::vector<const float *> steps = {flat.data(), bent.data()};
    size_t vertices = flat.size() / 3;
    same("mesh",
         render(device, settings,
                [&](hairtrace::Scene &s) { s.add_mesh_motion(vertices, steps, indices, 1); }),
         render(device, settings, [&](hairtrace::Scene &s) {
             uint32_t id = 0;
             hairtrace::check(ht_scene_add_mesh_motion(s.get(), vertices, flat.data(),
                                                       steps.data() + 1, 1, indices.size() / 3,
                                                       indices.data(), 1, &id));
         }));

    std::vector<float> stage = render(device, settings, [&](hairtrace::Scene &s) {
        hairtrace::Scene::Geometries ids = s.add_usd_file_at(usd, 6.0, HT_CURVE_AUTO, 0, &settings);
        std::printf("usd geometries %u %u\n", ids.first, ids.count);
    });
    same("usd", stage, render(device, settings, [&](hairtrace::Scene &s) {
             uint32_t first_id = 0, count = 0;
             hairtrace::check(ht_scene_add_usd_file_at(s.get(), usd.c_str(), 6.0, settings.get(),
                                                       HT_CURVE_AUTO, 0, &first_id, &count));
         }));
    /* Without the settings the shutter is closed: a still of frame 6. */
    std::vector<float> still = render(device, settings, [&](hairtrace::Scene &s) {
        s.add_usd_file_at(usd, 6.0, HT_CURVE_AUTO, 0);
    });
    std::printf("usd blurred %d\n", std::memcmp(stage.data(), still.data(), stage.size() * 4) != 0);

    hairtrace::Settings over_a_frame = blurred();
    over_a_frame.set("shutter_open", "0").set("shutter_close", "1");
    same("hair",
         render(device, over_a_frame,
                [&](hairtrace::Scene &s) {
                    s.add_hair_file_at(sequence, 1.0, true, HT_CURVE_LINEAR, HT_CURVE_ROUND, 0,
                                       &over_a_frame);
                }),
         render(device, over_a_frame, [&](hairtrace::Scene &s) {
             uint32_t id = 0;
             hairtrace::check(ht_scene_add_hair_file_at(s.get(), sequence.c_str(), 1.0,
                                                        over_a_frame.get(), true, HT_CURVE_LINEAR,
                                                        HT_CURVE_ROUND, 0, &id));
         }));

    /* A NaN at a later step throws, with the status and the step named. */
    third[6] = std::numeric_limits<float>::quiet_NaN();
    try {
        hairtrace::Scene scene(device);
        HtHairParams params = ht_hair_params_default();
        uint32_t hair = 0;
        hairtrace::check(ht_scene_add_hair_material(scene.get(), &params, &hair));
        scene.add_curves_xyzr_motion(desc, later, hair);
        std::printf("not refused\n");
    } catch (const hairtrace::Error &e) {
        std::printf("refused %d %s\n", static_cast<int>(e.status()), e.what());
    }
    return 0;
}
