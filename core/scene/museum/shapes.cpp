#include "core/scene/museum/shapes.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include <glm/gtc/constants.hpp>

namespace vitrine::scene::museum {

void rect(MeshBuilder& b, const Frame& f, float w, float h, glm::vec2 uvScale, int segX, int segY,
          const AoFunction& ao) {
    b.chart();
    glm::vec3 n = f.normal();
    std::vector<uint32_t> ids;
    for (int j = 0; j <= segY; ++j) {
        for (int i = 0; i <= segX; ++i) {
            float x = w * i / segX, y = h * j / segY;
            glm::vec3 p = f.at(x, y);
            glm::vec2 uv = (glm::vec2(x, -y) + f.uvOffset) * uvScale;
            ids.push_back(
                b.vertex(p, n, uv, glm::vec2(x, y), ao ? ao(glm::vec3(b.transform() * glm::vec4(p, 1.0f))) : 1.0f));
        }
    }
    for (int j = 0; j < segY; ++j) {
        for (int i = 0; i < segX; ++i) {
            uint32_t a = ids[j * (segX + 1) + i];
            b.quad(a, a + 1, a + segX + 2, a + segX + 1);
        }
    }
}

namespace {

// The front face of a slab minus its openings, as the cells of the grid through all opening edges.
void faceWithHoles(MeshBuilder& b, const Frame& f, float w, float h, std::span<const Opening> openings,
                   glm::vec2 uvScale) {
    std::vector<float> xs = {0.0f, w}, ys = {0.0f, h};
    for (const Opening& o : openings) {
        xs.insert(xs.end(), {o.x0, o.x1});
        ys.insert(ys.end(), {o.y0, o.y1});
    }
    for (std::vector<float>* axis : {&xs, &ys}) {
        std::sort(axis->begin(), axis->end());
        axis->erase(std::unique(axis->begin(), axis->end()), axis->end());
    }
    b.chart();
    glm::vec3 n = f.normal();
    std::map<std::pair<size_t, size_t>, uint32_t> ids;
    auto vertexAt = [&](size_t i, size_t j) {
        auto it = ids.find({i, j});
        if (it != ids.end()) return it->second;
        glm::vec2 uv = (glm::vec2(xs[i], -ys[j]) + f.uvOffset) * uvScale;
        uint32_t id = b.vertex(f.at(xs[i], ys[j]), n, uv, glm::vec2(xs[i], ys[j]));
        ids[{i, j}] = id;
        return id;
    };
    for (size_t j = 0; j + 1 < ys.size(); ++j) {
        for (size_t i = 0; i + 1 < xs.size(); ++i) {
            glm::vec2 c(0.5f * (xs[i] + xs[i + 1]), 0.5f * (ys[j] + ys[j + 1]));
            bool hole = std::any_of(openings.begin(), openings.end(), [&](const Opening& o) {
                return c.x > o.x0 && c.x < o.x1 && c.y > o.y0 && c.y < o.y1;
            });
            if (!hole) b.quad(vertexAt(i, j), vertexAt(i + 1, j), vertexAt(i + 1, j + 1), vertexAt(i, j + 1));
        }
    }
}

} // namespace

void slab(MeshBuilder& b, const Frame& f, float w, float h, float t, std::span<const Opening> openings,
          glm::vec2 uvScale, bool back, bool reveals, float revealBeyond) {
    glm::vec3 n = f.normal();
    faceWithHoles(b, f, w, h, openings, uvScale);
    if (back) {
        Frame bf{f.origin - n * t + f.u * w, -f.u, f.v, f.uvOffset};
        std::vector<Opening> mirrored;
        for (const Opening& o : openings)
            mirrored.push_back({w - o.x1, w - o.x0, o.y0, o.y1});
        faceWithHoles(b, bf, w, h, mirrored, uvScale);
    }
    for (const Opening& o : reveals ? openings : std::span<const Opening>()) {
        float ow = o.x1 - o.x0, oh = o.y1 - o.y0;
        const float deep = t + revealBeyond;
        rect(b, Frame{f.at(o.x0, o.y0), -n, f.v}, deep, oh, uvScale);           // left jamb, facing +u
        rect(b, Frame{f.at(o.x1, o.y0) - n * deep, n, f.v}, deep, oh, uvScale); // right jamb, facing -u
        // Sill facing +v; at y0 = 0 it is a doorway's threshold, closing the floor across the wall.
        rect(b, Frame{f.at(o.x0, o.y0), f.u, -n}, ow, t, uvScale);
        if (o.y1 < h) rect(b, Frame{f.at(o.x0, o.y1) - n * deep, f.u, n}, ow, deep, uvScale); // head, facing -v
    }
}

void box(MeshBuilder& b, const glm::vec3& lo, const glm::vec3& hi, float s) {
    glm::vec3 d = hi - lo;
    glm::vec2 uv(s);
    const glm::vec3 X(1, 0, 0), Y(0, 1, 0), Z(0, 0, 1);
    rect(b, Frame{{hi.x, lo.y, hi.z}, -Z, Y}, d.z, d.y, uv);
    rect(b, Frame{{lo.x, lo.y, lo.z}, Z, Y}, d.z, d.y, uv);
    rect(b, Frame{{lo.x, hi.y, hi.z}, X, -Z}, d.x, d.z, uv);
    rect(b, Frame{{lo.x, lo.y, lo.z}, X, Z}, d.x, d.z, uv);
    rect(b, Frame{{lo.x, lo.y, hi.z}, X, Y}, d.x, d.y, uv);
    rect(b, Frame{{hi.x, lo.y, lo.z}, -X, Y}, d.x, d.y, uv);
}

namespace {

// A profile as rings: one per point, two at sharp corners (hard edge), each with its 2D normal.
struct Ring {
    glm::vec2 p;      // (across, along) — (radius, height) for lathes, (side, up) for sweeps
    glm::vec2 normal; // outward in the same plane
    float arc;        // length along the profile
};

std::vector<Ring> rings(std::span<const glm::vec2> profile, bool closed) {
    size_t n = profile.size();
    size_t edges = closed ? n : n - 1;
    std::vector<glm::vec2> edgeNormal(edges);
    for (size_t e = 0; e < edges; ++e) {
        glm::vec2 d = profile[(e + 1) % n] - profile[e];
        float len = glm::length(d);
        edgeNormal[e] = len > 0.0f ? glm::vec2(d.y, -d.x) / len : glm::vec2(1, 0);
    }
    std::vector<Ring> out;
    float arc = 0.0f;
    for (size_t i = 0; i <= (closed ? n : n - 1); ++i) {
        size_t pi = i % n;
        if (i > 0) arc += glm::length(profile[pi] - profile[(i - 1) % n]);
        bool hasPrev = closed || i > 0, hasNext = closed ? i < n : i + 1 < n;
        glm::vec2 prev = hasPrev ? edgeNormal[(i + edges - 1) % edges] : edgeNormal[0];
        glm::vec2 next = hasNext ? edgeNormal[i % edges] : prev;
        if (!hasPrev) prev = next;
        if (glm::dot(prev, next) > 0.82f) { // < ~35°: smooth
            out.push_back({profile[pi], glm::normalize(prev + next), arc});
        } else {
            if (hasPrev) out.push_back({profile[pi], prev, arc});
            if (hasNext) out.push_back({profile[pi], next, arc});
        }
    }
    return out;
}

} // namespace

void lathe(MeshBuilder& b, std::span<const glm::vec2> profile, int segments, glm::vec2 uvScale) {
    std::vector<Ring> rs = rings(profile, false);
    float reference = 0.0f;
    for (const glm::vec2& p : profile)
        reference = std::max(reference, p.x);
    b.chart();
    std::vector<uint32_t> ids;
    for (const Ring& r : rs) {
        for (int k = 0; k <= segments; ++k) {
            float theta = glm::two_pi<float>() * k / segments;
            float c = std::cos(theta), s = std::sin(theta);
            glm::vec3 pos(r.p.x * c, r.p.y, -r.p.x * s);
            glm::vec3 nrm(r.normal.x * c, r.normal.y, -r.normal.x * s);
            glm::vec2 chart(theta * reference, r.arc);
            ids.push_back(b.vertex(pos, nrm, glm::vec2(chart.x, -chart.y) * uvScale, chart));
        }
    }
    int stride = segments + 1;
    for (size_t i = 0; i + 1 < rs.size(); ++i) {
        if (rs[i].p == rs[i + 1].p) continue; // the two rings of a hard edge
        for (int k = 0; k < segments; ++k) {
            uint32_t a = ids[i * stride + k];
            b.quad(a, a + 1, a + 1 + stride, a + stride);
        }
    }
}

void sphere(MeshBuilder& b, float radius, int ringCount, int segments, float uvScale) {
    std::vector<glm::vec2> profile;
    for (int i = 0; i <= ringCount; ++i) {
        float phi = glm::pi<float>() * i / ringCount;
        profile.emplace_back(radius * std::sin(phi), -radius * std::cos(phi));
    }
    profile.front().x = profile.back().x = 0.0f;
    lathe(b, profile, segments, glm::vec2(uvScale));
}

void sweep(MeshBuilder& b, std::span<const glm::vec3> path, bool closedPath, const glm::vec3& up,
           std::span<const glm::vec2> profile, bool closedProfile, bool smooth, float uvScale) {
    size_t n = path.size();
    size_t segments = closedPath ? n : n - 1;
    auto segTangent = [&](size_t s) { return glm::normalize(path[(s + 1) % n] - path[s]); };
    // Per path vertex: the mitre tangent (average of the two segments) for positions.
    std::vector<glm::vec3> mitre(n);
    for (size_t i = 0; i < n; ++i) {
        bool hasPrev = closedPath || i > 0, hasNext = closedPath || i + 1 < n;
        glm::vec3 t(0.0f);
        if (hasPrev) t += segTangent((i + n - 1) % n);
        if (hasNext) t += segTangent(i % n);
        mitre[i] = glm::normalize(t);
    }
    std::vector<Ring> rs = rings(profile, closedProfile);
    b.chart();
    float along = 0.0f;
    for (size_t s = 0; s < segments; ++s) {
        size_t i0 = s, i1 = (s + 1) % n;
        glm::vec3 st = segTangent(s);
        float length = glm::length(path[i1] - path[i0]);
        std::vector<uint32_t> ids;
        for (size_t end = 0; end < 2; ++end) {
            size_t i = end ? i1 : i0;
            glm::vec3 t = mitre[i];
            glm::vec3 side = glm::normalize(glm::cross(t, up));
            float stretch = 1.0f / std::max(0.2f, glm::dot(t, st)); // the mitre plane is wider than the section
            glm::vec3 nt = smooth ? t : st;
            glm::vec3 nSide = glm::normalize(glm::cross(nt, up)), nUp = glm::normalize(glm::cross(nSide, nt));
            glm::vec3 pUp = glm::normalize(glm::cross(side, t));
            for (const Ring& r : rs) {
                glm::vec3 pos = path[i] + side * (r.p.x * stretch) + pUp * r.p.y;
                glm::vec3 nrm = nSide * r.normal.x + nUp * r.normal.y;
                glm::vec2 chart(along + (end ? length : 0.0f), r.arc);
                ids.push_back(b.vertex(pos, nrm, glm::vec2(chart.x, -chart.y) * uvScale, chart));
            }
        }
        size_t m = rs.size();
        for (size_t r = 0; r + 1 < m; ++r) {
            if (rs[r].p == rs[r + 1].p) continue;
            // Along the path first, then around the profile: cross(tangent, profile direction) points out
            // for a profile that runs counter-clockwise in (side, up).
            b.quad(ids[r], ids[m + r], ids[m + r + 1], ids[r + 1]);
        }
        along += length;
    }
}

void surface(MeshBuilder& b, const std::function<glm::vec3(float, float)>& p, int ns, int nt, glm::vec2 size,
             glm::vec2 uvScale) {
    b.chart();
    std::vector<uint32_t> ids;
    const float e = 1e-3f;
    for (int j = 0; j <= nt; ++j) {
        for (int i = 0; i <= ns; ++i) {
            float s = float(i) / ns, t = float(j) / nt;
            glm::vec3 ds = p(std::min(s + e, 1.0f), t) - p(std::max(s - e, 0.0f), t);
            glm::vec3 dt = p(s, std::min(t + e, 1.0f)) - p(s, std::max(t - e, 0.0f));
            glm::vec3 n = glm::cross(ds, dt);
            float len = glm::length(n);
            // At a pole one derivative vanishes: step in a little to find the direction.
            if (len < 1e-12f) {
                float t2 = t < 0.5f ? t + 0.01f : t - 0.01f;
                n = glm::cross(p(std::min(s + e, 1.0f), t2) - p(std::max(s - e, 0.0f), t2), dt);
                len = glm::length(n);
            }
            n = len > 0.0f ? n / len : glm::vec3(0, 1, 0);
            glm::vec2 chart(s * size.x, t * size.y);
            ids.push_back(b.vertex(p(s, t), n, glm::vec2(chart.x, -chart.y) * uvScale, chart));
        }
    }
    for (int j = 0; j < nt; ++j) {
        for (int i = 0; i < ns; ++i) {
            uint32_t a = ids[j * (ns + 1) + i];
            b.quad(a, a + 1, a + ns + 2, a + ns + 1);
        }
    }
}

std::vector<glm::vec2> smoothProfile(std::span<const glm::vec2> control, int samples) {
    std::vector<glm::vec2> out;
    size_t n = control.size();
    for (int i = 0; i < samples; ++i) {
        float x = float(i) / (samples - 1) * (n - 1);
        size_t k = std::min(static_cast<size_t>(x), n - 2);
        float t = x - k;
        glm::vec2 p0 = control[k == 0 ? 0 : k - 1], p1 = control[k], p2 = control[k + 1];
        glm::vec2 p3 = control[std::min(k + 2, n - 1)];
        float t2 = t * t, t3 = t2 * t;
        out.push_back(0.5f * ((2.0f * p1) + (-p0 + p2) * t + (2.0f * p0 - 5.0f * p1 + 4.0f * p2 - p3) * t2 +
                              (-p0 + 3.0f * p1 - 3.0f * p2 + p3) * t3));
    }
    return out;
}

std::vector<glm::vec3> arc(const glm::vec3& center, const glm::vec3& a, const glm::vec3& b, float r, float angle0,
                           float angle1, int segments) {
    std::vector<glm::vec3> out;
    for (int i = 0; i <= segments; ++i) {
        float t = angle0 + (angle1 - angle0) * i / segments;
        out.push_back(center + r * (a * std::cos(t) + b * std::sin(t)));
    }
    return out;
}

std::vector<glm::vec2> circleProfile(float r, int segments) {
    std::vector<glm::vec2> out;
    for (int i = 0; i < segments; ++i) {
        float t = glm::two_pi<float>() * i / segments;
        out.emplace_back(r * std::cos(t), r * std::sin(t));
    }
    return out;
}

} // namespace vitrine::scene::museum
