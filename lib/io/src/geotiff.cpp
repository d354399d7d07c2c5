// GeoTIFF in memory: libtiff over a growable buffer (encode) or a read-only span (decode),
// GeoKeys through libgeotiff (docs/dataset-format.md).
#include <geotiff.h>
#include <geovalues.h>
#include <tiffio.h>
#include <xtiffio.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <memory>
#include <mutex>

#include "nsg/core/error.h"
#include "nsg/core/strings.h"
#include "nsg/geometry/georef.h"
#include "nsg/io/raster.h"

namespace nsg::io {
namespace {

constexpr uint32_t kRowsPerStrip = 256;
// A corrupt header must not make us allocate without bound: tiles are 256 x 256, so a
// header claiming more than 4096 x 4096 pixels is refused before any buffer is made.
constexpr uint32_t kMaxSidePx = 4096;

// ---- libtiff client I/O over memory -------------------------------------------------------

struct MemFile {
  std::vector<uint8_t>* out = nullptr;  // encode: grows as libtiff writes
  std::span<const uint8_t> in;          // decode: read-only
  uint64_t pos = 0;
  std::string error;  // libtiff's messages, for our exceptions

  uint64_t size() const { return out != nullptr ? out->size() : in.size(); }
  const uint8_t* data() const { return out != nullptr ? out->data() : in.data(); }
};

tmsize_t mem_read(thandle_t h, void* buf, tmsize_t n) {
  auto* f = static_cast<MemFile*>(h);
  if (n <= 0 || f->pos >= f->size()) return 0;
  const uint64_t count = std::min<uint64_t>(static_cast<uint64_t>(n), f->size() - f->pos);
  std::memcpy(buf, f->data() + f->pos, count);
  f->pos += count;
  return static_cast<tmsize_t>(count);
}

tmsize_t mem_write(thandle_t h, void* buf, tmsize_t n) {
  auto* f = static_cast<MemFile*>(h);
  if (f->out == nullptr || n < 0) return -1;
  const uint64_t end = f->pos + static_cast<uint64_t>(n);
  if (end > f->out->size()) f->out->resize(end);
  std::memcpy(f->out->data() + f->pos, buf, static_cast<size_t>(n));
  f->pos = end;
  return n;
}

toff_t mem_seek(thandle_t h, toff_t offset, int whence) {
  auto* f = static_cast<MemFile*>(h);
  int64_t base = 0;
  if (whence == SEEK_CUR) base = static_cast<int64_t>(f->pos);
  if (whence == SEEK_END) base = static_cast<int64_t>(f->size());
  const int64_t target = base + static_cast<int64_t>(offset);
  if (target < 0) return static_cast<toff_t>(-1);
  f->pos = static_cast<uint64_t>(target);  // past the end is fine: a later write fills the gap
  return f->pos;
}

int mem_close(thandle_t) { return 0; }
toff_t mem_size(thandle_t h) { return static_cast<MemFile*>(h)->size(); }
int mem_map(thandle_t, void**, toff_t*) { return 0; }  // 0 = not mapped: libtiff reads instead
void mem_unmap(thandle_t, void*, toff_t) {}

int on_tiff_error(TIFF*, void* user, const char* module, const char* fmt, va_list ap) {
  char text[512];
  std::vsnprintf(text, sizeof text, fmt, ap);
  auto* f = static_cast<MemFile*>(user);
  if (!f->error.empty()) f->error += "; ";
  f->error += (module != nullptr ? std::string(module) + ": " : std::string()) + text;
  return 1;  // handled: nothing on stderr
}
int on_tiff_warning(TIFF*, void*, const char*, const char*, va_list) { return 1; }

// ---- tags -----------------------------------------------------------------------------------

TIFFExtendProc g_parent_extender = nullptr;

// GDAL's nodata and metadata tags: ASCII, as GDAL itself registers them.
void extend_with_gdal_tags(TIFF* tif) {
  static const TIFFFieldInfo kFields[] = {
      {TIFFTAG_GDAL_NODATA, -1, -1, TIFF_ASCII, FIELD_CUSTOM, 1, 0, const_cast<char*>("GDALNoDataValue")},
      {TIFFTAG_GDAL_METADATA, -1, -1, TIFF_ASCII, FIELD_CUSTOM, 1, 0, const_cast<char*>("GDALMetadata")}};
  TIFFMergeFieldInfo(tif, kFields, 2);
  if (g_parent_extender != nullptr) g_parent_extender(tif);
}

// Registers the GeoTIFF tags (libgeotiff's extender) and GDAL_NODATA once per process.
void register_tags() {
  static std::once_flag once;
  std::call_once(once, [] {
    XTIFFInitialize();
    g_parent_extender = TIFFSetTagExtender(extend_with_gdal_tags);
  });
}

struct TiffCloser {
  void operator()(TIFF* t) const { TIFFClose(t); }
};
using TiffPtr = std::unique_ptr<TIFF, TiffCloser>;
struct GtifFreer {
  void operator()(GTIF* g) const { GTIFFree(g); }
};
using GtifPtr = std::unique_ptr<GTIF, GtifFreer>;

TiffPtr open_tiff(const std::string& name, const char* mode, MemFile& mem) {
  register_tags();
  std::unique_ptr<TIFFOpenOptions, void (*)(TIFFOpenOptions*)> opts(TIFFOpenOptionsAlloc(), TIFFOpenOptionsFree);
  TIFFOpenOptionsSetErrorHandlerExtR(opts.get(), on_tiff_error, &mem);
  TIFFOpenOptionsSetWarningHandlerExtR(opts.get(), on_tiff_warning, &mem);
  TIFF* tif = TIFFClientOpenExt(name.c_str(), mode, &mem, mem_read, mem_write, mem_seek, mem_close, mem_size, mem_map,
                                mem_unmap, opts.get());
  return TiffPtr(tif);
}

// ---- encode ---------------------------------------------------------------------------------

void check_encodable(const Raster& r, const GeoTiffOptions& options) {
  const bool u8 = r.type == SampleType::kUInt8 && (r.bands == 1 || r.bands == 3);
  const bool f32 = r.type == SampleType::kFloat32 && r.bands == 1;
  NSG_CHECK(u8 || f32, DataError, "", "raster",
            "GeoTIFF encoding supports uint8 1- or 3-band "
            "and float32 1-band rasters, got " +
                std::to_string(r.bands) + " band(s) of " + (r.type == SampleType::kUInt8 ? "uint8" : "float32"));
  NSG_CHECK(options.band_descriptions.size() <= static_cast<size_t>(r.bands), ConfigError, "", "band_descriptions",
            "at most one per band (" + std::to_string(r.bands) + ")");
  NSG_CHECK(options.color_table.empty() || (r.type == SampleType::kUInt8 && r.bands == 1), ConfigError, "",
            "color_table", "a 1-band uint8 raster (a palette maps its values)");
  if (options.nodata && r.type == SampleType::kUInt8) {
    const double v = *options.nodata;
    NSG_CHECK(v >= 0.0 && v <= 255.0 && v == std::floor(v), ConfigError, "", "nodata",
              "an integer in 0..255 for a uint8 raster, got " + format_double(v));
  }
}

std::string nodata_text(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return format_double(v);
}

// Text inside GDAL_METADATA's XML.
std::string xml_escaped(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '&') out += "&amp;";
    else if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else out += c;
  }
  return out;
}

// GDAL_METADATA as GDAL writes it: per-band items carry sample="<band index>", the
// description role="description".
std::string gdal_metadata(const GeoTiffOptions& options) {
  std::string xml = "<GDALMetadata>\n";
  for (const auto& [name, value] : options.band_metadata)
    xml += "  <Item name=\"" + name + "\" sample=\"0\">" + xml_escaped(value) + "</Item>\n";
  for (size_t b = 0; b < options.band_descriptions.size(); ++b)
    xml += "  <Item name=\"DESCRIPTION\" sample=\"" + std::to_string(b) + "\" role=\"description\">" +
           xml_escaped(options.band_descriptions[b]) + "</Item>\n";
  return xml + "</GDALMetadata>";
}

// TIFF ColorMap: 3 × 256 16-bit values (8-bit colours scaled by 257).
void set_color_map(TIFF* tif, const std::vector<std::array<uint8_t, 3>>& table) {
  std::array<std::array<uint16_t, 256>, 3> map{};
  for (size_t i = 0; i < table.size(); ++i)
    for (int c = 0; c < 3; ++c) map[c][i] = static_cast<uint16_t>(table[i][c] * 257);
  TIFFSetField(tif, TIFFTAG_COLORMAP, map[0].data(), map[1].data(), map[2].data());
}

void set_image_tags(TIFF* tif, const Raster& r, const GeoTiffOptions& options) {
  const bool f32 = r.type == SampleType::kFloat32;
  TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, static_cast<uint32_t>(r.width));
  TIFFSetField(tif, TIFFTAG_IMAGELENGTH, static_cast<uint32_t>(r.height));
  TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, static_cast<uint16_t>(r.bands));
  TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, static_cast<uint16_t>(f32 ? 32 : 8));
  TIFFSetField(tif, TIFFTAG_SAMPLEFORMAT, static_cast<uint16_t>(f32 ? SAMPLEFORMAT_IEEEFP : SAMPLEFORMAT_UINT));
  const uint16_t photometric = !options.color_table.empty() ? PHOTOMETRIC_PALETTE
                               : r.bands == 3               ? PHOTOMETRIC_RGB
                                                            : PHOTOMETRIC_MINISBLACK;
  TIFFSetField(tif, TIFFTAG_PHOTOMETRIC, photometric);
  if (!options.color_table.empty()) set_color_map(tif, options.color_table);
  TIFFSetField(tif, TIFFTAG_PLANARCONFIG, static_cast<uint16_t>(PLANARCONFIG_CONTIG));
  TIFFSetField(tif, TIFFTAG_ORIENTATION, static_cast<uint16_t>(ORIENTATION_TOPLEFT));
  TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, std::min<uint32_t>(r.height, kRowsPerStrip));
  TIFFSetField(tif, TIFFTAG_COMPRESSION, static_cast<uint16_t>(COMPRESSION_ADOBE_DEFLATE));
  TIFFSetField(tif, TIFFTAG_ZIPQUALITY, options.deflate_level);
  if (options.nodata) TIFFSetField(tif, TIFFTAG_GDAL_NODATA, nodata_text(*options.nodata).c_str());
  if (!options.band_descriptions.empty() || !options.band_metadata.empty())
    TIFFSetField(tif, TIFFTAG_GDAL_METADATA, gdal_metadata(options).c_str());
}

// The user-defined spherical azimuthal-equidistant CRS, key for key as docs/dataset-format.md lists.
void set_geokeys(TIFF* tif, const GeoRef& g) {
  const auto& loc = geometry::location_info(g.location);
  GtifPtr gt(GTIFNew(tif));
  if (!gt) throw InternalError("", "GeoTIFF", "libgeotiff could not attach to the TIFF");
  GTIF* k = gt.get();
  GTIFKeySet(k, GTModelTypeGeoKey, TYPE_SHORT, 1, ModelTypeProjected);
  GTIFKeySet(k, GTRasterTypeGeoKey, TYPE_SHORT, 1, RasterPixelIsArea);
  GTIFKeySet(k, GeographicTypeGeoKey, TYPE_SHORT, 1, KvUserDefined);
  GTIFKeySet(k, GeogGeodeticDatumGeoKey, TYPE_SHORT, 1, KvUserDefined);
  GTIFKeySet(k, GeogEllipsoidGeoKey, TYPE_SHORT, 1, KvUserDefined);
  GTIFKeySet(k, GeogSemiMajorAxisGeoKey, TYPE_DOUBLE, 1, geometry::kDevkitEarthRadiusM);
  GTIFKeySet(k, GeogSemiMinorAxisGeoKey, TYPE_DOUBLE, 1, geometry::kDevkitEarthRadiusM);
  GTIFKeySet(k, GeogAngularUnitsGeoKey, TYPE_SHORT, 1, Angular_Degree);
  GTIFKeySet(k, GeogPrimeMeridianLongGeoKey, TYPE_DOUBLE, 1, 0.0);
  GTIFKeySet(k, ProjectedCSTypeGeoKey, TYPE_SHORT, 1, KvUserDefined);
  GTIFKeySet(k, ProjectionGeoKey, TYPE_SHORT, 1, KvUserDefined);
  GTIFKeySet(k, ProjCoordTransGeoKey, TYPE_SHORT, 1, CT_AzimuthalEquidistant);
  GTIFKeySet(k, ProjLinearUnitsGeoKey, TYPE_SHORT, 1, Linear_Meter);
  GTIFKeySet(k, ProjFalseEastingGeoKey, TYPE_DOUBLE, 1, 0.0);
  GTIFKeySet(k, ProjFalseNorthingGeoKey, TYPE_DOUBLE, 1, 0.0);
  GTIFKeySet(k, ProjCenterLongGeoKey, TYPE_DOUBLE, 1, loc.origin_lon_deg);
  GTIFKeySet(k, ProjCenterLatGeoKey, TYPE_DOUBLE, 1, loc.origin_lat_deg);
  if (!GTIFWriteKeys(k)) throw InternalError("", "GeoTIFF", "libgeotiff could not write GeoKeys");

  const double tiepoint[6] = {0.0, 0.0, 0.0, g.x_west_m, g.y_north_m, 0.0};
  const double scale[3] = {g.resolution_m, g.resolution_m, 0.0};
  TIFFSetField(tif, TIFFTAG_GEOTIEPOINTS, 6, tiepoint);
  TIFFSetField(tif, TIFFTAG_GEOPIXELSCALE, 3, scale);
}

void write_strips(TIFF* tif, const Raster& r, MemFile& mem) {
  const size_t row_bytes = static_cast<size_t>(r.width) * r.bands * r.bytes_per_sample();
  uint32_t strip = 0;
  for (uint32_t row = 0; row < static_cast<uint32_t>(r.height); row += kRowsPerStrip, ++strip) {
    const uint32_t rows = std::min<uint32_t>(kRowsPerStrip, r.height - row);
    // libtiff writes into the buffer only for predictors or byte swapping; we use neither.
    auto* src = const_cast<uint8_t*>(r.data.data() + row * row_bytes);
    if (TIFFWriteEncodedStrip(tif, strip, src, static_cast<tmsize_t>(rows * row_bytes)) < 0) {
      throw InternalError("", "GeoTIFF strip " + std::to_string(strip), "libtiff could not encode: " + mem.error);
    }
  }
}

// ---- decode ---------------------------------------------------------------------------------

struct Layout {
  uint32_t width = 0, height = 0;
  uint16_t bands = 1, bits = 8, format = SAMPLEFORMAT_UINT, planar = PLANARCONFIG_CONTIG;
};

Layout read_layout(TIFF* tif, const std::string& name) {
  Layout l;
  NSG_CHECK(!TIFFIsTiled(tif), ParseError, name, "TIFF layout", "a striped TIFF, found a tiled one");
  NSG_CHECK(TIFFGetField(tif, TIFFTAG_IMAGEWIDTH, &l.width) == 1 &&
                TIFFGetField(tif, TIFFTAG_IMAGELENGTH, &l.height) == 1 && l.width > 0 && l.height > 0,
            ParseError, name, "ImageWidth/ImageLength", "a positive image size");
  TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLESPERPIXEL, &l.bands);
  TIFFGetFieldDefaulted(tif, TIFFTAG_BITSPERSAMPLE, &l.bits);
  TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLEFORMAT, &l.format);
  TIFFGetFieldDefaulted(tif, TIFFTAG_PLANARCONFIG, &l.planar);
  const bool u8 = l.bits == 8 && l.format == SAMPLEFORMAT_UINT && (l.bands == 1 || l.bands == 3);
  const bool f32 = l.bits == 32 && l.format == SAMPLEFORMAT_IEEEFP && l.bands == 1;
  NSG_CHECK(u8 || f32, ParseError, name, "TIFF sample layout",
            "uint8 with 1 or 3 samples per pixel or float32 with 1, got " + std::to_string(l.bands) + " sample(s) of " +
                std::to_string(l.bits) + " bits, SampleFormat " + std::to_string(l.format));
  NSG_CHECK(l.bands == 1 || l.planar == PLANARCONFIG_CONTIG, ParseError, name, "PlanarConfig",
            "contiguous (pixel-interleaved) samples");
  return l;
}

void read_strips(TIFF* tif, Raster& r, const std::string& name, MemFile& mem) {
  uint32_t rows_per_strip = 0;
  TIFFGetFieldDefaulted(tif, TIFFTAG_ROWSPERSTRIP, &rows_per_strip);
  rows_per_strip = std::clamp<uint32_t>(rows_per_strip, 1, r.height);
  const size_t row_bytes = static_cast<size_t>(r.width) * r.bands * r.bytes_per_sample();
  const uint32_t strips = (r.height + rows_per_strip - 1) / rows_per_strip;
  NSG_CHECK(TIFFNumberOfStrips(tif) == strips, ParseError, name, "StripOffsets",
            std::to_string(strips) + " strips, found " + std::to_string(TIFFNumberOfStrips(tif)));
  for (uint32_t s = 0; s < strips; ++s) {
    const uint32_t row = s * rows_per_strip;
    const uint32_t rows = std::min<uint32_t>(rows_per_strip, r.height - row);
    const auto want = static_cast<tmsize_t>(rows * row_bytes);
    const tmsize_t got = TIFFReadEncodedStrip(tif, s, r.data.data() + row * row_bytes, want);
    NSG_CHECK(got == want, ParseError, name, "strip " + std::to_string(s),
              std::to_string(want) + " decoded bytes" + (mem.error.empty() ? "" : " (libtiff: " + mem.error + ")"));
  }
}

// Location whose origin equals the file's projection centre, or "" if none.
std::string match_location(double lat_deg, double lon_deg) {
  for (const auto& loc : geometry::known_locations()) {
    if (std::abs(loc.origin_lat_deg - lat_deg) < 1e-12 && std::abs(loc.origin_lon_deg - lon_deg) < 1e-12) {
      return std::string(loc.name);
    }
  }
  return "";
}

GeoRef read_georef(TIFF* tif, const std::string& name) {
  uint16_t n_tie = 0, n_scale = 0;
  double* tie = nullptr;
  double* scale = nullptr;
  NSG_CHECK(TIFFGetField(tif, TIFFTAG_GEOTIEPOINTS, &n_tie, &tie) == 1 && n_tie >= 6, ParseError, name,
            "ModelTiepointTag", "a tiepoint (i, j, k, x, y, z)");
  NSG_CHECK(TIFFGetField(tif, TIFFTAG_GEOPIXELSCALE, &n_scale, &scale) == 1 && n_scale >= 2, ParseError, name,
            "ModelPixelScaleTag", "a pixel scale (sx, sy, sz)");
  NSG_CHECK(tie[0] == 0.0 && tie[1] == 0.0, ParseError, name, "ModelTiepointTag", "the tiepoint at raster (0, 0)");
  NSG_CHECK(scale[0] > 0.0 && scale[0] == scale[1], ParseError, name, "ModelPixelScaleTag",
            "square positive pixels, got " + format_double(scale[0]) + " x " + format_double(scale[1]));
  GeoRef g;
  g.x_west_m = tie[3];
  g.y_north_m = tie[4];
  g.resolution_m = scale[0];
  GtifPtr gt(GTIFNew(tif));
  double lat = NAN, lon = NAN;
  if (gt && GTIFKeyGet(gt.get(), ProjCenterLatGeoKey, &lat, 0, 1) == 1 &&
      GTIFKeyGet(gt.get(), ProjCenterLongGeoKey, &lon, 0, 1) == 1) {
    g.location = match_location(lat, lon);
  }
  return g;
}

}  // namespace

std::vector<uint8_t> encode_geotiff(const Raster& raster, const GeoRef& georef, const GeoTiffOptions& options) {
  raster.validate();
  georef.validate();
  options.validate();
  check_encodable(raster, options);
  std::vector<uint8_t> out;
  out.reserve(raster.data.size() / 2 + 4096);
  MemFile mem;
  mem.out = &out;
  {
    TiffPtr tif = open_tiff("<memory>", "w", mem);
    if (!tif) throw InternalError("", "GeoTIFF", "libtiff could not open a memory TIFF: " + mem.error);
    set_image_tags(tif.get(), raster, options);
    set_geokeys(tif.get(), georef);
    write_strips(tif.get(), raster, mem);
    if (!TIFFFlush(tif.get())) {
      throw InternalError("", "GeoTIFF", "libtiff could not write the directory: " + mem.error);
    }
  }
  return out;
}

namespace {

// Opens `bytes` for reading through `mem` (which must outlive the handle); a ParseError
// naming `name` when libtiff refuses them.
TiffPtr open_for_reading(std::span<const uint8_t> bytes, const std::string& name, MemFile& mem) {
  mem.in = bytes;
  TiffPtr tif = open_tiff(name, "r", mem);
  NSG_CHECK(tif != nullptr, ParseError, name, "TIFF header",
            "a TIFF file" + (mem.error.empty() ? std::string() : " (libtiff: " + mem.error + ")"));
  return tif;
}

}  // namespace

RasterHeader read_geotiff_header(std::span<const uint8_t> bytes, const std::string& name) {
  MemFile mem;
  TiffPtr tif = open_for_reading(bytes, name, mem);
  const Layout l = read_layout(tif.get(), name);
  return {static_cast<int>(l.width), static_cast<int>(l.height), l.bands,
          l.bits == 32 ? SampleType::kFloat32 : SampleType::kUInt8};
}

std::string describe(const RasterHeader& h) {
  return std::to_string(h.width) + " x " + std::to_string(h.height) + " " +
         (h.type == SampleType::kFloat32 ? "float32" : "uint8") + " x " + std::to_string(h.bands);
}

void check_raster_header(const RasterHeader& got, const RasterHeader& want, const std::string& name,
                         const std::string& record) {
  NSG_CHECK(got.width == want.width && got.height == want.height && got.bands == want.bands && got.type == want.type,
            DataError, name, record,
            "a raster of " + describe(want) + " (the manifest's tile format), got " + describe(got));
}

Raster decode_geotiff(std::span<const uint8_t> bytes, const std::string& name, GeoRef* georef) {
  MemFile mem;
  TiffPtr tif = open_for_reading(bytes, name, mem);
  const Layout l = read_layout(tif.get(), name);
  NSG_CHECK(l.width <= kMaxSidePx && l.height <= kMaxSidePx, ParseError, name, "ImageWidth/ImageLength",
            "an image of at most " + std::to_string(kMaxSidePx) + " x " + std::to_string(kMaxSidePx) + " pixels, got " +
                std::to_string(l.width) + " x " + std::to_string(l.height));
  Raster r;
  r.width = static_cast<int>(l.width);
  r.height = static_cast<int>(l.height);
  r.bands = l.bands;
  r.type = l.bits == 32 ? SampleType::kFloat32 : SampleType::kUInt8;
  r.data.resize(uint64_t{l.width} * l.height * l.bands * (l.bits / 8));
  read_strips(tif.get(), r, name, mem);
  if (georef != nullptr) *georef = read_georef(tif.get(), name);
  return r;
}

}  // namespace nsg::io
