#include "nodes/camera/lens.hpp"

#include "core/base/error.hpp"
#include "core/graph/json_util.hpp"
#include "shaders/camera/exposure.h"

#include <algorithm>
#include <cmath>
#include <set>

namespace vitrine::camera {
namespace {

using nlohmann::json;

class Reader {
public:
    Reader(std::string file) : mFile(std::move(file)) {}

    [[noreturn]] void fail(const std::string& pointer, const std::string& message) const {
        throw UserError(mFile + ": " + (pointer.empty() ? "/" : pointer) + ": " + message);
    }
    const json& member(const json& obj, const std::string& pointer, const std::string& key) const {
        auto it = obj.find(key);
        if (it == obj.end()) fail(pointer + "/" + key, "missing (see data/lenses/README.md for the format)");
        return *it;
    }
    float number(const json& v, const std::string& pointer, double lo, double hi) const {
        if (!v.is_number() || v.get<double>() < lo || v.get<double>() > hi)
            fail(pointer, "expected a number in [" + fmt(lo) + ", " + fmt(hi) + "], got " + brief(v));
        return v.get<float>();
    }
    float number(const json& obj, const std::string& pointer, const std::string& key, double lo, double hi) const {
        return number(member(obj, pointer, key), pointer + "/" + key, lo, hi);
    }
    std::vector<std::pair<float, float>> table(const json& obj, const std::string& pointer, const std::string& key,
                                               double lo, double hi) const {
        const json& t = member(obj, pointer, key);
        const std::string at = pointer + "/" + key;
        if (!t.is_array() || t.empty()) fail(at, "expected a non-empty array of [focal_mm, f_number] pairs");
        std::vector<std::pair<float, float>> out;
        for (size_t i = 0; i < t.size(); ++i) {
            const std::string row = at + "/" + std::to_string(i);
            if (!t[i].is_array() || t[i].size() != 2) fail(row, "expected [focal_mm, f_number], got " + brief(t[i]));
            const float f = number(t[i][0], row + "/0", 1.0, 2000.0);
            if (!out.empty() && f <= out.back().first) fail(row + "/0", "focal lengths must increase from row to row");
            out.emplace_back(f, number(t[i][1], row + "/1", lo, hi));
        }
        return out;
    }
    Correction correction(const json& obj, const std::string& pointer, const std::string& key) const {
        const json& c = member(obj, pointer, key);
        const std::string at = pointer + "/" + key;
        if (!c.is_object()) fail(at, "expected {\"type\": \"none\" | \"profile\", \"strength\": 0..1}");
        const json& type = member(c, at, "type");
        Correction out;
        if (type == "none") out.type = Correction::Type::None;
        else if (type == "profile") out.type = Correction::Type::Profile;
        else fail(at + "/type", "expected \"none\" or \"profile\", got " + brief(type));
        out.strength = number(c, at, "strength", 0.0, 1.0);
        return out;
    }

private:
    static std::string fmt(double v) {
        std::string s = std::to_string(v);
        s.erase(s.find_last_not_of('0') + 1);
        if (!s.empty() && s.back() == '.') s.pop_back();
        return s;
    }
    std::string mFile;
};

} // namespace

LensData loadLens(const std::filesystem::path& path) {
    const json doc = readJsonFile(path);
    const Reader r(path.string());
    if (!doc.is_object()) r.fail("", "expected a lens object (format vitrine-lens/1)");
    if (r.member(doc, "", "format") != "vitrine-lens/1")
        r.fail("/format", "expected \"vitrine-lens/1\": not a lens file"); // its content is not echoed
    LensData lens;
    lens.file = path.string();
    const json& name = r.member(doc, "", "name");
    if (!name.is_string() || name.get<std::string>().empty()) r.fail("/name", "expected a non-empty string");
    lens.name = name.get<std::string>();
    for (const char* key : {"sources", "estimates"})
        if (!r.member(doc, "", key).is_string()) r.fail(std::string("/") + key, "expected a string (where the numbers come from)");

    const json& sensor = r.member(doc, "", "sensor_mm");
    if (!sensor.is_array() || sensor.size() != 2) r.fail("/sensor_mm", "expected [width, height] in mm");
    lens.sensorWidthMm = r.number(sensor[0], "/sensor_mm/0", 1.0, 100.0);
    lens.sensorHeightMm = r.number(sensor[1], "/sensor_mm/1", 1.0, 100.0);

    const json& range = r.member(doc, "", "focal_length_mm");
    if (!range.is_array() || range.size() != 2) r.fail("/focal_length_mm", "expected [shortest, longest] in mm");
    lens.focalMinMm = r.number(range[0], "/focal_length_mm/0", 1.0, 2000.0);
    lens.focalMaxMm = r.number(range[1], "/focal_length_mm/1", lens.focalMinMm, 2000.0);

    lens.maxAperture = r.table(doc, "", "max_aperture", 0.7, 64.0);
    lens.minAperture = r.table(doc, "", "min_aperture", 0.7, 128.0);
    for (float f : {lens.focalMinMm, lens.focalMaxMm})
        if (interpolate(lens.minAperture, f) < interpolate(lens.maxAperture, f))
            r.fail("/min_aperture", "the smallest aperture's f-number is below the maximum aperture's at " +
                                        std::to_string(static_cast<int>(f)) + " mm");
    lens.minFocusM = r.number(doc, "", "min_focus_m", 0.01, 100.0);
    if (lens.minFocusM * 1000.0f <= lens.focalMaxMm) r.fail("/min_focus_m", "must exceed the longest focal length");
    const json& blades = r.member(doc, "", "blades");
    if (!blades.is_number_integer() || blades.get<int>() < 0 || blades.get<int>() == 1 || blades.get<int>() == 2 ||
        blades.get<int>() > 20)
        r.fail("/blades", "expected 0 (a circle) or an integer in [3, 20], got " + brief(blades));
    lens.blades = blades.get<int>();
    lens.bladeRoundness = r.number(doc, "", "blade_roundness", 0.0, 1.0);
    lens.focusBreathing = r.number(doc, "", "focus_breathing", -0.5, 0.5);

    const json& ab = r.member(doc, "", "aberrations");
    if (!ab.is_array() || ab.empty()) r.fail("/aberrations", "expected a non-empty array of per-focal-length rows");
    for (size_t i = 0; i < ab.size(); ++i) {
        const std::string at = "/aberrations/" + std::to_string(i);
        if (!ab[i].is_object()) r.fail(at, "expected an object");
        Aberrations a;
        a.focalMm = r.number(ab[i], at, "focal_mm", 1.0, 2000.0);
        if (!lens.aberrations.empty() && a.focalMm <= lens.aberrations.back().focalMm)
            r.fail(at + "/focal_mm", "focal lengths must increase from row to row");
        a.k1 = r.number(ab[i], at, "distortion_k1", -0.5, 0.5);
        a.k2 = r.number(ab[i], at, "distortion_k2", -0.5, 0.5);
        a.caRed = r.number(ab[i], at, "ca_red", 0.98, 1.02);
        a.caBlue = r.number(ab[i], at, "ca_blue", 0.98, 1.02);
        a.vignettingStops = r.number(ab[i], at, "vignetting_stops", 0.0, 6.0);
        lens.aberrations.push_back(a);
    }
    const json& corr = r.member(doc, "", "correction");
    if (!corr.is_object()) r.fail("/correction", "expected an object with distortion, ca and vignetting");
    lens.distortion = r.correction(corr, "/correction", "distortion");
    lens.ca = r.correction(corr, "/correction", "ca");
    lens.vignetting = r.correction(corr, "/correction", "vignetting");
    return lens;
}

std::filesystem::path findLens(const std::string& nameOrPath, const std::filesystem::path& graphDir,
                               const std::filesystem::path& dataDir) {
    namespace fs = std::filesystem;
    const fs::path lenses = dataDir / "lenses";
    fs::path p;
    if (fs::path(nameOrPath).extension() == ".json") {
        p = fs::path(nameOrPath).is_absolute() ? fs::path(nameOrPath) : graphDir / nameOrPath;
        if (!fs::is_regular_file(p)) throw UserError("no lens file " + p.string());
        return p;
    }
    p = lenses / (nameOrPath + ".json");
    if (!nameOrPath.empty() && nameOrPath.find('/') == std::string::npos && fs::is_regular_file(p)) return p;
    std::set<std::string> names;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(lenses, ec))
        if (e.path().extension() == ".json") names.insert(e.path().stem().string());
    std::string list;
    for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
    throw UserError("no lens '" + nameOrPath + "': expected a .json file or one of data/lenses/: " + list);
}

float interpolate(const std::vector<std::pair<float, float>>& table, float focalMm) {
    if (focalMm <= table.front().first) return table.front().second;
    if (focalMm >= table.back().first) return table.back().second;
    for (size_t i = 1; i < table.size(); ++i)
        if (focalMm <= table[i].first) {
            const auto [f0, v0] = table[i - 1];
            const auto [f1, v1] = table[i];
            return v0 + (v1 - v0) * (focalMm - f0) / (f1 - f0);
        }
    return table.back().second;
}

LensState evaluateLens(const LensData& lens, float focalMm, float focusM, float fNumber) {
    auto column = [&](float Aberrations::*member) {
        std::vector<std::pair<float, float>> t;
        for (const auto& a : lens.aberrations) t.emplace_back(a.focalMm, a.*member);
        return interpolate(t, focalMm);
    };
    LensState s;
    const float f = focalMm * 1e-3f;
    const float d = std::max(focusM, lens.minFocusM);
    const float m = f / (d - f), mMin = f / (lens.minFocusM - f);
    s.focalLengthMm = focalMm * (1.0f + lens.focusBreathing * m / mMin);
    s.wideOpenFNumber = interpolate(lens.maxAperture, focalMm);
    s.minFNumber = interpolate(lens.minAperture, focalMm);
    s.k1 = column(&Aberrations::k1) * lens.distortion.residual();
    s.k2 = column(&Aberrations::k2) * lens.distortion.residual();
    s.caRed = 1.0f + (column(&Aberrations::caRed) - 1.0f) * lens.ca.residual();
    s.caBlue = 1.0f + (column(&Aberrations::caBlue) - 1.0f) * lens.ca.residual();
    const float halfDiagonal = 0.5f * std::hypot(lens.sensorWidthMm, lens.sensorHeightMm);
    const float cosTheta = focalMm / std::hypot(focalMm, halfDiagonal);
    const float naturalStops = -std::log2(std::pow(cosTheta, 4.0f));
    const float mechanicalStops = std::max(0.0f, column(&Aberrations::vignettingStops) - naturalStops);
    s.mechanicalWideOpen = (1.0f - std::exp2(-mechanicalStops)) * lens.vignetting.residual();
    s.mechanicalVignetting = gpu_types::cameraMechanicalVignetting(
        s.mechanicalWideOpen, gpu_types::cameraStopsDown(fNumber, s.wideOpenFNumber));
    return s;
}

} // namespace vitrine::camera
