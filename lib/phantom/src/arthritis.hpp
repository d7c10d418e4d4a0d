#pragma once
// The changes of an arthritic hip, placed on a head's model surface (see
// phantom.hpp: FlatDome, Osteophytes, Cyst, NarrowGap), and their record in
// truth.json.
#include <nlohmann/json.hpp>

#include "articula/geometry/surface.hpp"
#include "articula/phantom/phantom.hpp"

namespace articula::phantom::detail {

/// Places the departures the options ask for on `hip`, whose head (model
/// surface `head`, mean radius r0) and neck axis are set; the neck's radius
/// locates the head-neck junction. Seeded parts (the lip's arc, the cysts)
/// draw from their own stream, so a seed keeps its head and noise.
void addArthritis(const PhantomOptions& o, const geometry::PosedSurface& head, double r0, double neck_radius, Hip& hip);

/// truth.json's `departures` of a hip (an empty array when it has none).
nlohmann::json departuresJson(const Hip& hip, const PhantomOptions& o);

/// Reads `departures` back into a hip (the parts headSurfaceDistance and the
/// socket use).
void departuresFromJson(const nlohmann::json& departures, Hip& hip);

}  // namespace articula::phantom::detail
