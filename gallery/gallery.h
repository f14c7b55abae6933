#pragma once
/// The gallery: per species a preview of the final stage and a strip of growth stages,
/// and an index.html linking them. renderGalleryItem is self-contained (species file in,
/// files and figures out), so a sharded gallery can run any subset of items anywhere and
/// build the index from the items' figures.

#include <filesystem>
#include <string>
#include <vector>

#include "core/diagnostics.h"
#include "model/yaml_reader.h"

namespace sprig {

/// How much to render.
enum class GalleryQuality { Draft, Final };

/// What one species produced.
struct GalleryItem {
  std::string source;       ///< species file as given
  std::string name;
  std::string description;
  std::string kind;
  std::string mode;         ///< how the final image was rendered: exact, mesh or skeleton
  std::string preview;      ///< file name of the final-stage image inside the gallery folder
  std::string strip;        ///< file name of the growth-stage strip
  std::string animation;    ///< file name of the growth animation (GIF, app/animate.h)
  int frames = 0;           ///< frames in the animation
  size_t primitives = 0;    ///< render primitives of the final stage (internodes + organs)
  size_t triangles = 0;     ///< triangles of the final stage's polygon organs
  std::vector<int> stages;  ///< stages shown in the strip: derivation steps (trees) or ages in degrees (shells)
  size_t modules = 0;
  size_t internodes = 0;
  int steps = 0;
  double deriveSeconds = 0;  ///< building the final stage: derivation, turtle, BlobTree, compile
  double renderSeconds = 0;  ///< the three pictures: the still, the strip and the animation
  double stillSeconds = 0;      ///< of renderSeconds: the final stage's picture
  double stripSeconds = 0;      ///< of renderSeconds: the growth strip
  double animationSeconds = 0;  ///< of renderSeconds: the animation
  std::string error;        ///< non-empty when the species failed (the diagnostics)
};

/// Renders one species into outDir (images written atomically). Never throws for bad
/// input: the diagnostics go to item.error. Throws Cancelled on a signal.
GalleryItem renderGalleryItem(const std::filesystem::path& speciesFile, const std::filesystem::path& outDir,
                              GalleryQuality quality, const PathPolicy& policy);

/// The HTML of index.html for items (in order): a grid of thumbnails grouped by kind (trees,
/// shells, organisms, solids, BlobTree models), a filter box (every word must occur in the
/// name, description, kind, figure set or file name) and buttons for the papers' figure
/// sets. Each card links to the species' page (gallerySpeciesPageHtml).
std::string galleryIndexHtml(const std::vector<GalleryItem>& items);

/// The HTML of the page of items[index] (`pages/STEM.html`): the final stage, the growth
/// strip, the animation, the figures, and links to the index and its neighbours.
std::string gallerySpeciesPageHtml(const std::vector<GalleryItem>& items, size_t index);

/// The figure set of a species file's stem ("fig_shell_07a_varix_spines" -> "Murex cabritii
/// shell (Galbraith et al.)"), from the prefixes the shipped files use; empty when none.
std::string galleryFigureSet(const std::string& stem);

/// `pages/STEM.html`, where a species' page is written.
std::string galleryPageFile(const GalleryItem& item);
/// `thumbs/STEM.png` (320 x 240, the final stage scaled to fit), empty when it has none.
std::string galleryThumbFile(const GalleryItem& item);

}  // namespace sprig
