/// \file
/// Research settings: ablations that turn one idea of a technique's paper off, for measuring what
/// each is worth (`mrgi replay --dlpv-ablation / --dir-ablation / --specular-ablation`, `mrgi
/// bench --specular-ablation`). An app does not need this header: RuntimeSettings::research left
/// null runs every technique as published.
#pragma once
#include <memory>

namespace mrgi {

/// Ablations of the `dlpv` technique (DLPV paper Sec. 4: what each of its ideas is worth; the
/// defaults are the paper's method). Read at start-up.
struct DlpvAblation {
  /// The paper's V^Delta by delta injection (+R^rho - R^mu into one volume, eq. 13) replaced by
  /// two volumes, V^rho and V^mu, propagated separately and subtracted where a real pixel looks
  /// them up (the differential rendering of Debevec's kind the paper improves on). Levels with
  /// shadow-mapped direct light only (the paper level's antiradiance shadows need V^Delta).
  bool two_volumes = false;
  bool no_negative_damping = false;  ///< propagate V^Delta without damping negative flux (Sec. 4.4)
  bool no_half_cell_shift = false;   ///< inject VPLs at their surface, not half a cell along the normal
  /// V^rho (the virtual pixels' bounce light) from the real surfaces' VPLs only, without the
  /// virtual objects' light onto themselves (which a volume of cells about an object's size
  /// cannot resolve: perf/results/dlpv/ablation says what it does to the frames).
  bool no_virtual_self_bounce = false;
  bool any() const { return two_volumes || no_negative_damping || no_half_cell_shift || no_virtual_self_bounce; }
};

/// Ablations of the `dir` technique (DIR paper Sec. 3.3 and 3.7: what its ideas for the VPLs are
/// worth; the defaults are the paper's method). Read at start-up. They change the VPL light; the
/// lamps' direct light is the direct-light block's two shadow maps either way (no_environment_vpls also gives
/// the fast levels' environment regions back to the direct-light block's maps).
struct DirAblation {
  /// One shadow map per lamp and one imperfect shadow map per VPL holding the nearest surface,
  /// real or virtual, with a flag for which (Knecht et al. 2010, the paper's [4]), instead of one
  /// each: a real caster behind a virtual one no longer shadows L_r (the double shadow of the
  /// paper's Fig. 5), in the lamps' direct light and in the VPLs' light.
  bool one_shadow_map = false;
  /// No ir(VPL): the real surfaces a virtual object hides from the lamp get no VPLs of their own
  /// (VPL 3 of Fig. 6), so the real bounce the object blocks is not taken away from L_r (the
  /// inconsistent colour bleeding of Fig. 14).
  bool no_real_only_vpls = false;
  /// One bounce: no bounce light source (Sec. 3.7), its VPL slots go to the lamps, so the light
  /// stops after the lamps' VPLs (the levels with multiple bounces only).
  bool one_bounce = false;
  /// No environment VPLs (Sec. 3.7): the environment's regions the direct-light block does not shadow stay its
  /// unshadowed SH ambient, so a virtual object casts no shadow of that light.
  bool no_environment_vpls = false;
  /// No temporal smoothing of the VPL light (the paper's [4]: blending the previous frame's by a
  /// confidence from normal, position and illumination change): each frame's VPLs alone.
  bool no_temporal_smoothing = false;
  /// No caustic VPLs (caustics-DIR paper Sec. 4.2.2): a VPL drawn on a mirror or glass object
  /// stays there as on any surface instead of moving to where its light lands.
  bool no_caustic_vpls = false;
  bool any() const {
    return one_shadow_map || no_real_only_vpls || one_bounce || no_environment_vpls || no_temporal_smoothing ||
           no_caustic_vpls;
  }
};

/// Reflective and refractive virtual objects (Knecht et al. 2013) without one of the paper's
/// ideas, for ablation images; every technique (the specular stage runs after any of them).
struct SpecularAblation {
  /// Off: mirrors and glass are shaded by the technique like any material (its diffuse and
  /// glossy light), as before the stage existed.
  bool off = false;
  /// No back-projection (Sec. 4.1.2): every real surface seen in a mirror or through glass shows
  /// its rendered light, not the camera's colour.
  bool no_back_projection = false;
  /// No depth validity test (Sec. 4.1.3): a back-projected hit takes the camera's colour even
  /// where the camera sees another surface there.
  bool no_depth_test = false;
  /// No caustics (Sec. 4.2): a spot lamp's light through a mirror or glass lights nothing.
  bool no_caustics = false;
  bool any() const { return off || no_back_projection || no_depth_test || no_caustics; }
};

/// Every ablation, read at start-up (RuntimeSettings::research).
struct ResearchSettings {
  DlpvAblation dlpv;          ///< the `dlpv` technique only
  DirAblation dir;            ///< the `dir` technique only
  SpecularAblation specular;  ///< every technique (the specular stage)
  bool any() const { return dlpv.any() || dir.any() || specular.any(); }
};

/// The settings' research block, or the published methods' defaults when none is set.
template <class Settings>
const ResearchSettings& research_of(const Settings& s) {
  static const ResearchSettings published;
  return s.research ? *s.research : published;
}

}  // namespace mrgi
