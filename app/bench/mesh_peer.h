// OpenSCAD's mesh of a scene as a peer on the report's mesh axis (what exact CSG buys): the scene
// written as an OpenSCAD model (scad_export.h), meshed by the `openscad` executable (CGAL's exact
// booleans on the primitives faceted at `$fn`) into an STL, whose triangles Embree traces; their
// primary hits are compared with the exact image of the same run by their surfaces alone.
#pragma once

#include <string>

#include "engine/scene/scene.h"

namespace lancer::bench {

/// One meshing of the model.
struct MeshRun {
    std::string failure;  ///< why there is no mesh (empty when there is one)
    double meshMs = 0.0;  ///< the openscad process, start to end
    std::string stl;      ///< the mesh written
};

class MeshPeer {
  public:
    /// True when an `openscad` executable is on the PATH (or $LANCER_OPENSCAD names one).
    static bool available();
    /// "OpenSCAD version 2021.01"; empty if none.
    static std::string version();
    /// The executable run.
    static std::string executable();

    /// Write the scene as OUT/openscad/`name`.scad. Throws std::invalid_argument for a scene
    /// OpenSCAD cannot model (a surface).
    MeshPeer(const Scene& scene, const std::string& outDir, const std::string& name);

    /// Mesh the model at `fn` segments a circle into OUT/openscad/`name`-fnN.stl; openscad is
    /// stopped after `timeoutSeconds`.
    MeshRun mesh(int fn, double timeoutSeconds) const;
    /// The scene modelled (its camera, lights and materials see the mesh).
    const Scene* scene() const { return scene_; }

  private:
    const Scene* scene_;
    std::string dir_, name_;
};

/// The triangles of an STL file (ASCII or binary) as a union of triangles, seen as `like` is
/// (its camera, lights, background and materials). Throws SceneError naming the file and line.
Scene readStl(const std::string& path, const Scene& like);

}  // namespace lancer::bench
