// Limit positions and normals of a tagged control mesh refined 0..N levels, with OpenSubdiv 3.5,
// in the format of shared/golden/opensubdiv (see README.md here). Not part of CI.
//
// Usage: osd-golden loop|catmark MESH.obj OUTPREFIX [LEVELS=3]
// Writes OUTPREFIX.L{k}.lim and OUTPREFIX.L{k}.lim.faces for k = 0..LEVELS.
//
// Semi-sharp features: OpenSubdiv's PrimvarRefiner::Limit applies the crease/corner limit masks
// wherever sharpness > 0 remains, which is not the limit while that sharpness is finite. Here the
// mesh is refined further, until no finite sharpness is left, and the limit of a level-k vertex
// is taken at its first descendant (vertex-child chain) whose own sharpness and incident edge
// sharpnesses are all 0 or infinite (>= 10): that vertex has the same limit point and normal.
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using namespace OpenSubdiv;

struct Vtx {
    double p[3];
    void Clear(void * = 0) { p[0] = p[1] = p[2] = 0.0; }
    void AddWithWeight(Vtx const &s, double w) {
        for (int k = 0; k < 3; ++k) p[k] += w * s.p[k];
    }
};

static Far::TopologyRefiner::UniformOptions uniform(int levels) {
    Far::TopologyRefiner::UniformOptions u(levels);
    u.fullTopologyInLastLevel = true;  // Limit() needs the last level's full topology
    return u;
}

static bool semiSharp(float s) { return s > 0.0f && s < Sdc::Crease::SHARPNESS_INFINITE; }

int main(int argc, char **argv) {
    if (argc < 4) {
        std::fprintf(stderr, "usage: %s loop|catmark MESH.obj OUTPREFIX [LEVELS]\n", argv[0]);
        return 2;
    }
    std::string scheme = argv[1];
    int levels = argc > 4 ? std::atoi(argv[4]) : 3;
    std::ifstream in(argv[2]);
    if (!in) {
        std::fprintf(stderr, "cannot read %s\n", argv[2]);
        return 2;
    }
    std::vector<double> pos;
    std::vector<int> nverts, indices, creaseVerts, cornerVerts;
    std::vector<float> creaseW, cornerW;
    float maxFinite = 0.0f;
    std::string line;
    while (std::getline(in, line)) {
        std::istringstream ls(line);
        std::string tok;
        if (!(ls >> tok)) continue;
        if (tok == "v") {
            double x, y, z;
            ls >> x >> y >> z;
            pos.insert(pos.end(), {x, y, z});
        } else if (tok == "f") {
            int n = 0;
            while (ls >> tok) {
                indices.push_back(std::atoi(tok.c_str()) - 1);
                ++n;
            }
            nverts.push_back(n);
        } else if (tok == "t") {
            std::string kind, counts;
            ls >> kind >> counts;
            float s;
            if (kind == "crease") {
                int a, b;
                ls >> a >> b >> s;
                creaseVerts.insert(creaseVerts.end(), {a, b});
                creaseW.push_back(s);
            } else if (kind == "corner") {
                int v;
                ls >> v >> s;
                cornerVerts.push_back(v);
                cornerW.push_back(s);
            } else {
                continue;
            }
            if (semiSharp(s) && s > maxFinite) maxFinite = s;
        }
    }
    Far::TopologyDescriptor desc;
    desc.numVertices = (int)pos.size() / 3;
    desc.numFaces = (int)nverts.size();
    desc.numVertsPerFace = nverts.data();
    desc.vertIndicesPerFace = indices.data();
    desc.numCreases = (int)creaseW.size();
    desc.creaseVertexIndexPairs = creaseVerts.data();
    desc.creaseWeights = creaseW.data();
    desc.numCorners = (int)cornerW.size();
    desc.cornerVertexIndices = cornerVerts.data();
    desc.cornerWeights = cornerW.data();

    Sdc::Options opts;
    opts.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
    opts.SetCreasingMethod(Sdc::Options::CREASE_UNIFORM);
    Sdc::SchemeType type = scheme == "loop" ? Sdc::SCHEME_LOOP : Sdc::SCHEME_CATMARK;
    typedef Far::TopologyRefinerFactory<Far::TopologyDescriptor> Factory;
    Far::TopologyRefiner *refiner =
        Factory::Create(desc, Factory::Options(type, opts));
    if (!refiner) return 1;
    int extra = (int)std::ceil(maxFinite) + 1;
    int maxLevel = levels + extra;
    refiner->RefineUniform(uniform(maxLevel));

    // Positions at every level, and limit position/tangents at every level.
    std::vector<std::vector<Vtx>> P(maxLevel + 1), LP(maxLevel + 1), T1(maxLevel + 1),
        T2(maxLevel + 1);
    P[0].resize(desc.numVertices);
    for (int i = 0; i < desc.numVertices; ++i)
        for (int k = 0; k < 3; ++k) P[0][i].p[k] = pos[3 * i + k];
    Far::PrimvarRefinerReal<double> primvar(*refiner);
    for (int l = 1; l <= maxLevel; ++l) {
        P[l].resize(refiner->GetLevel(l).GetNumVertices());
        primvar.Interpolate(l, P[l - 1], P[l]);
    }
    // Limit() evaluates at a refiner's last level, so each level gets a refiner of its own.
    for (int l = 0; l <= maxLevel; ++l) {
        size_t n = P[l].size();
        LP[l].resize(n);
        T1[l].resize(n);
        T2[l].resize(n);
    }
    for (int l = 0; l <= maxLevel; ++l) {
        Far::TopologyRefiner *r = Factory::Create(desc, Factory::Options(type, opts));
        if (l > 0) r->RefineUniform(uniform(l));
        Far::PrimvarRefinerReal<double> pv(*r);
        pv.Limit(P[l], LP[l], T1[l], T2[l]);
        delete r;
    }
    for (int L = 0; L <= levels; ++L) {
        Far::TopologyLevel const &lev = refiner->GetLevel(L);
        int n = lev.GetNumVertices();
        std::string base = std::string(argv[3]) + ".L" + std::to_string(L) + ".lim";
        FILE *f = std::fopen(base.c_str(), "w");
        std::fprintf(f, "%d\n", n);
        for (int v = 0; v < n; ++v) {
            int l = L, x = v;
            for (;;) {
                Far::TopologyLevel const &cur = refiner->GetLevel(l);
                bool semi = semiSharp(cur.GetVertexSharpness(x));
                Far::ConstIndexArray es = cur.GetVertexEdges(x);
                for (int i = 0; i < es.size(); ++i) semi = semi || semiSharp(cur.GetEdgeSharpness(es[i]));
                if (!semi) break;
                if (l == maxLevel) {
                    std::fprintf(stderr, "sharpness left at level %d\n", l);
                    return 1;
                }
                x = cur.GetVertexChildVertex(x);
                ++l;
            }
            double const *a = T1[l][x].p, *b = T2[l][x].p;
            double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                           a[0] * b[1] - a[1] * b[0]};
            double len = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
            double const *p = LP[l][x].p;
            std::fprintf(f, "%.17g %.17g %.17g %.17g %.17g %.17g\n", p[0], p[1], p[2], c[0] / len,
                         c[1] / len, c[2] / len);
        }
        std::fclose(f);
        FILE *g = std::fopen((base + ".faces").c_str(), "w");
        for (int face = 0; face < lev.GetNumFaces(); ++face) {
            Far::ConstIndexArray fv = lev.GetFaceVertices(face);
            for (int i = 0; i < fv.size(); ++i) std::fprintf(g, i ? " %d" : "%d", fv[i]);
            std::fprintf(g, "\n");
        }
        std::fclose(g);
    }
    delete refiner;
    return 0;
}
