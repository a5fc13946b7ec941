// Colour exports of a display profile (see results/colour_export.h). Thin: the curve comes from
// the profile, OpenColorIO writes and reads CLF/CTF/.cube/config, Little CMS writes and reads ICC.
// No exception crosses into C: every entry point catches and reports through csf_error.
// csfcal's C headers have no extern "C" guards of their own (except ours): give them C linkage.
extern "C" {
#include "core/csf_status.h"
#include "results/display_profile.h"
#include "core/file_write.h"
}
#include "results/colour_export.h"

#include <OpenColorIO/OpenColorIO.h>
#include <lcms2.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace OCIO = OCIO_NAMESPACE;

namespace {

const char *const kNames[CSF_EXPORT_COUNT] = {"clf", "ctf", "cube", "icc", "ocio"};
const char *const kExt[CSF_EXPORT_COUNT] = {".clf", ".ctf", ".cube", ".icc", ".ocio"};

// Luminance relative to white, black included: L(v) / L(1). Every export carries this one curve,
// so Y(0) = black / white > 0 and cd/m2 = Y * white (the ICC's luminance tag, the description).
double rel_lum(const csf_display_profile *p, double v)
{
    return csf_profile_rel_lum(p, v); // the one definition (results/display_profile.h), as display info
}

OCIO::Lut1DTransformRcPtr make_lut(const csf_display_profile *p)
{
    OCIO::Lut1DTransformRcPtr lut = OCIO::Lut1DTransform::Create();
    lut->setLength(CSF_EXPORT_LUT_SIZE);
    for (unsigned long i = 0; i < CSF_EXPORT_LUT_SIZE; i++) {
        float y = (float)rel_lum(p, (double)i / (CSF_EXPORT_LUT_SIZE - 1));
        lut->setValue(i, y, y, y);
    }
    lut->setFileOutputBitDepth(OCIO::BIT_DEPTH_F32);
    lut->setInterpolation(OCIO::INTERP_LINEAR);
    return lut;
}

std::string describe(const csf_display_profile *p)
{
    std::ostringstream d;
    d.precision(10);
    d << "csfcal display profile " << csf_profile_id(p) << ": drive (R=G=B) to luminance relative to "
      << "white, black included (1 = white = " << csf_profile_lum_max(p) << " cd/m2; drive 0 gives "
      << "black = " << csf_profile_lum_black(p) << " cd/m2; cd/m2 = value * white); measured "
      << csf_profile_created_utc(p) << " with " << csf_profile_instrument(p);
    return d.str();
}

// A config with a linear reference and this display's drive space.
OCIO::ConfigRcPtr make_config(const csf_display_profile *p, const std::string &lut_file)
{
    OCIO::ConfigRcPtr cfg = OCIO::Config::CreateRaw()->createEditableCopy();
    cfg->setMajorVersion(2);
    cfg->setMinorVersion(0);
    cfg->setDescription(describe(p).c_str());
    OCIO::ColorSpaceRcPtr lin = OCIO::ColorSpace::Create();
    lin->setName("linear");
    lin->setDescription("display luminance relative to the white of the calibrated monitor, linear, black included (drive 0 gives black / white)");
    lin->setIsData(false);
    cfg->addColorSpace(lin);
    OCIO::ColorSpaceRcPtr drv = OCIO::ColorSpace::Create();
    drv->setName("csfcal_display");
    drv->setDescription(describe(p).c_str());
    if (lut_file.empty()) {
        drv->setTransform(make_lut(p), OCIO::COLORSPACE_DIR_TO_REFERENCE);
    } else {
        OCIO::FileTransformRcPtr ft = OCIO::FileTransform::Create();
        ft->setSrc(lut_file.c_str());
        ft->setInterpolation(OCIO::INTERP_LINEAR);
        drv->setTransform(ft, OCIO::COLORSPACE_DIR_TO_REFERENCE);
    }
    cfg->addColorSpace(drv);
    cfg->setRole(OCIO::ROLE_SCENE_LINEAR, "linear");
    cfg->setRole(OCIO::ROLE_DEFAULT, "linear");
    cfg->addDisplayView("csfcal", "calibrated", "csfcal_display", "");
    cfg->setActiveDisplays("csfcal");
    cfg->setActiveViews("calibrated");
    cfg->setSearchPath(".");
    return cfg;
}

const char *write_format_name(const char *ext)
{
    for (int i = 0; i < OCIO::GroupTransform::GetNumWriteFormats(); i++)
        if (std::strcmp(OCIO::GroupTransform::GetFormatExtensionByIndex(i), ext + 1) == 0)
            return OCIO::GroupTransform::GetFormatNameByIndex(i);
    return nullptr;
}

// Every export is built in memory and then written through file_write (temporary beside the
// destination, fsync, rename), so a full disk leaves the old file and no part of a new one.
csf_status write_text(const std::string &text, const char *path, const char *what, csf_error *err)
{
    return csf_write_file_atomic(path, what, text.data(), text.size(), err);
}

csf_status group_text(const csf_display_profile *p, const char *ext, std::string &out, csf_error *err)
{
    const char *fmt = write_format_name(ext);
    if (!fmt) return csf_error_set(err, CSF_E_UNSUPPORTED, "this OpenColorIO cannot write %s files", ext);
    OCIO::GroupTransformRcPtr g = OCIO::GroupTransform::Create();
    g->getFormatMetadata().addAttribute("id", csf_profile_id(p));
    g->getFormatMetadata().addChildElement(OCIO::METADATA_DESCRIPTION, describe(p).c_str());
    g->appendTransform(make_lut(p));
    std::ostringstream os;
    g->write(OCIO::Config::CreateRaw(), fmt, os);
    out = os.str();
    return CSF_OK;
}

csf_status write_group(const csf_display_profile *p, const char *ext, const char *path, csf_error *err)
{
    std::string text;
    csf_status st = group_text(p, ext, text, err);
    if (st) return st;
    return write_text(text, path, ext[1] == 'c' && ext[2] == 'l' ? "CLF file" : "CTF file", err);
}

csf_status write_cube(const csf_display_profile *p, const char *path, csf_error *err)
{
    OCIO::ConfigRcPtr cfg = make_config(p, "");
    OCIO::BakerRcPtr baker = OCIO::Baker::Create();
    baker->setConfig(cfg);
    baker->setFormat("resolve_cube");
    baker->setInputSpace("csfcal_display");
    baker->setTargetSpace("linear");
    baker->setShaperSize(CSF_EXPORT_LUT_SIZE);
    // no 3-D part: the transform has no channel crosstalk, so the Resolve baker writes a pure 1-D
    // LUT (a 3-D cube could not hold 1e-4 accuracy along the grey axis)
    baker->setCubeSize(-1);
    baker->getFormatMetadata().addChildElement(OCIO::METADATA_DESCRIPTION, describe(p).c_str());
    std::ostringstream os;
    baker->bake(os);
    return write_text(os.str(), path, ".cube LUT", err);
}

// Writes text through an open atomic file; the caller commits or aborts.
csf_status put_text(csf_atomic_file *af, const std::string &text, csf_error *err)
{
    if (std::fwrite(text.data(), 1, text.size(), af->fp) != text.size()) {
        int e = errno;
        return csf_error_set(err, CSF_E_IO, "cannot write %s %s: %s", af->what, af->path, std::strerror(e));
    }
    return CSF_OK;
}

csf_status write_ocio(const csf_display_profile *p, const char *path, csf_error *err)
{
    // the LUT goes beside the config, named after it, and is found through search_path "."
    std::string base(path);
    size_t slash = base.find_last_of('/');
    std::string dir = slash == std::string::npos ? "" : base.substr(0, slash + 1);
    std::string name = slash == std::string::npos ? base : base.substr(slash + 1);
    size_t dot = name.find_last_of('.');
    if (dot != std::string::npos && dot > 0) name = name.substr(0, dot);
    std::string lut_name = name + ".clf";
    std::string lut_text;
    csf_status st = group_text(p, ".clf", lut_text, err);
    if (st) return st;
    OCIO::ConfigRcPtr cfg = make_config(p, lut_name);
    cfg->validate(); // throws with OpenColorIO's reason if the config would not load
    std::ostringstream os;
    cfg->serialize(os);
    // both files are complete on disk before either is renamed: a full disk leaves the old pair
    csf_atomic_file lut_f = {}, cfg_f = {};
    std::string lut_path = dir + lut_name;
    st = csf_atomic_open(&lut_f, lut_path.c_str(), "OCIO config LUT", err);
    if (!st) st = csf_atomic_open(&cfg_f, path, "OCIO config", err);
    if (!st) st = put_text(&lut_f, lut_text, err);
    if (!st) st = put_text(&cfg_f, os.str(), err);
    if (!st) {
        st = csf_atomic_commit(&lut_f, err);
        if (!st) return csf_atomic_commit(&cfg_f, err);
    }
    csf_atomic_abort(&lut_f);
    csf_atomic_abort(&cfg_f);
    return st;
}

cmsCIEXYZ xyY_to_XYZ(const cmsCIExyY &c)
{
    cmsCIEXYZ r;
    cmsxyY2XYZ(&r, &c);
    return r;
}

// Primaries and white chromaticities from the measured XYZ when known, else Rec.709/D65.
void chromaticities(const csf_display_profile *p, cmsCIExyYTRIPLE *prim, cmsCIExyY *white)
{
    *prim = {{0.64, 0.33, 1}, {0.30, 0.60, 1}, {0.15, 0.06, 1}};
    *white = {0.3127, 0.3290, 1};
    double rgbw[4][3];
    if (!csf_profile_primaries_xyz(p, rgbw)) return;
    for (int s = 0; s < 4; s++) {
        double sum = rgbw[s][0] + rgbw[s][1] + rgbw[s][2];
        if (!(sum > 0) || !(rgbw[s][1] > 0)) return;
    }
    cmsCIExyY *dst[4] = {&prim->Red, &prim->Green, &prim->Blue, white};
    for (int s = 0; s < 4; s++) {
        double sum = rgbw[s][0] + rgbw[s][1] + rgbw[s][2];
        *dst[s] = {rgbw[s][0] / sum, rgbw[s][1] / sum, 1};
    }
}

// The grey curve as a 16-bit table of CSF_ICC_TRC_SIZE entries, black included: Y(0) = black /
// white, so relative colorimetry through the matrix/TRC model gives black where the display has it.
cmsToneCurve *icc_curve(const csf_display_profile *p)
{
    std::vector<cmsUInt16Number> t(CSF_ICC_TRC_SIZE);
    for (size_t i = 0; i < t.size(); i++) {
        double y = rel_lum(p, (double)i / (CSF_ICC_TRC_SIZE - 1));
        t[i] = (cmsUInt16Number)std::lround(std::fmin(std::fmax(y, 0.0), 1.0) * 65535.0);
    }
    return cmsBuildTabulatedToneCurve16(nullptr, (cmsUInt32Number)t.size(), t.data());
}

bool write_text_tag(cmsHPROFILE h, cmsTagSignature sig, const std::string &text)
{
    cmsMLU *m = cmsMLUalloc(nullptr, 1);
    bool ok = m && cmsMLUsetASCII(m, "en", "US", text.c_str()) && cmsWriteTag(h, sig, m);
    cmsMLUfree(m);
    return ok;
}

bool invert3(const double a[9], double out[9])
{
    double det = a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
                 a[2] * (a[3] * a[7] - a[4] * a[6]);
    if (!(std::fabs(det) > 1e-12)) return false;
    out[0] = (a[4] * a[8] - a[5] * a[7]) / det;
    out[1] = (a[2] * a[7] - a[1] * a[8]) / det;
    out[2] = (a[1] * a[5] - a[2] * a[4]) / det;
    out[3] = (a[5] * a[6] - a[3] * a[8]) / det;
    out[4] = (a[0] * a[8] - a[2] * a[6]) / det;
    out[5] = (a[2] * a[3] - a[0] * a[5]) / det;
    out[6] = (a[3] * a[7] - a[4] * a[6]) / det;
    out[7] = (a[1] * a[6] - a[0] * a[7]) / det;
    out[8] = (a[0] * a[4] - a[1] * a[3]) / det;
    return true;
}

// A float curve: constant y_lo below x_lo, then sampled segments over [x_lo, x_hi] (breaks[k]
// split it; uniform samples inside each), constant y_hi above. `f` gives the exact value.
template <class F>
cmsToneCurve *segmented_curve(const std::vector<double> &breaks, const std::vector<int> &points, F f)
{
    size_t ns = points.size();
    std::vector<cmsCurveSegment> seg(ns + 2);
    std::vector<std::vector<cmsFloat32Number>> samples(ns);
    seg[0] = {};
    seg[0].x0 = -1e22f;
    seg[0].x1 = (cmsFloat32Number)breaks[0];
    seg[0].Type = 6; // (a x + b)^g + c with a = b = 0, g = 1: the constant c
    seg[0].Params[0] = 1;
    seg[0].Params[3] = f(breaks[0]);
    for (size_t k = 0; k < ns; k++) {
        // the first sample of a sampled segment is implicit (the end of the one before)
        samples[k].resize(points[k]);
        for (int i = 0; i < points[k]; i++)
            samples[k][i] = (cmsFloat32Number)f(breaks[k] + (breaks[k + 1] - breaks[k]) * i / (points[k] - 1));
        seg[k + 1] = {};
        seg[k + 1].x0 = (cmsFloat32Number)breaks[k];
        seg[k + 1].x1 = (cmsFloat32Number)breaks[k + 1];
        seg[k + 1].Type = 0;
        seg[k + 1].nGridPoints = (cmsUInt32Number)points[k];
        seg[k + 1].SampledPoints = samples[k].data();
    }
    seg[ns + 1] = {};
    seg[ns + 1].x0 = (cmsFloat32Number)breaks[ns];
    seg[ns + 1].x1 = 1e22f;
    seg[ns + 1].Type = 6;
    seg[ns + 1].Params[0] = 1;
    seg[ns + 1].Params[3] = f(breaks[ns]);
    return cmsBuildSegmentedToneCurve(nullptr, (cmsUInt32Number)seg.size(), seg.data());
}

// v4.3 floating-point tags (multiProcessElement, ICC.1:2010 10.14): the same curve and colorants
// as the TRC/matrix model, without its 16-bit rounding, for CMMs that evaluate in float (Little CMS
// prefers them). D2B device -> PCS, B2D back; every intent gets the same pipelines.
bool add_float_tags(cmsHPROFILE h, const csf_display_profile *p)
{
    const cmsCIEXYZ *col[3] = {(const cmsCIEXYZ *)cmsReadTag(h, cmsSigRedColorantTag),
                               (const cmsCIEXYZ *)cmsReadTag(h, cmsSigGreenColorantTag),
                               (const cmsCIEXYZ *)cmsReadTag(h, cmsSigBlueColorantTag)};
    if (!col[0] || !col[1] || !col[2]) return false;
    double fwd[9], back[9]; // rows X, Y, Z; columns r, g, b
    for (int c = 0; c < 3; c++) {
        fwd[c] = col[c]->X;
        fwd[3 + c] = col[c]->Y;
        fwd[6 + c] = col[c]->Z;
    }
    if (!invert3(fwd, back)) return false;
    double white = csf_profile_lum_max(p), y0 = rel_lum(p, 0);
    cmsToneCurve *to = segmented_curve({0.0, 1.0}, {CSF_ICC_TRC_SIZE}, [&](double v) { return rel_lum(p, v); });
    // the inverse is steep just above black: a finer segment there
    double knee = y0 + 0.01 * (1 - y0);
    cmsToneCurve *from = segmented_curve({y0, knee, 1.0}, {1024, CSF_ICC_TRC_SIZE}, [&](double y) {
        return csf_profile_grey_drive(p, y * white);
    });
    bool ok = to && from;
    cmsPipeline *d2b = cmsPipelineAlloc(nullptr, 3, 3), *b2d = cmsPipelineAlloc(nullptr, 3, 3);
    if (ok && d2b && b2d) {
        cmsToneCurve *tc[3] = {to, to, to}, *fc[3] = {from, from, from};
        ok = cmsPipelineInsertStage(d2b, cmsAT_END, cmsStageAllocToneCurves(nullptr, 3, tc)) &&
             cmsPipelineInsertStage(d2b, cmsAT_END, cmsStageAllocMatrix(nullptr, 3, 3, fwd, nullptr)) &&
             cmsPipelineInsertStage(b2d, cmsAT_END, cmsStageAllocMatrix(nullptr, 3, 3, back, nullptr)) &&
             cmsPipelineInsertStage(b2d, cmsAT_END, cmsStageAllocToneCurves(nullptr, 3, fc));
        ok = ok && cmsWriteTag(h, cmsSigDToB0Tag, d2b) && cmsWriteTag(h, cmsSigBToD0Tag, b2d);
        const cmsTagSignature d[3] = {cmsSigDToB1Tag, cmsSigDToB2Tag, cmsSigDToB3Tag};
        const cmsTagSignature b[3] = {cmsSigBToD1Tag, cmsSigBToD2Tag, cmsSigBToD3Tag};
        for (int k = 0; ok && k < 3; k++)
            ok = cmsLinkTag(h, d[k], cmsSigDToB0Tag) && cmsLinkTag(h, b[k], cmsSigBToD0Tag);
    } else {
        ok = false;
    }
    if (d2b) cmsPipelineFree(d2b);
    if (b2d) cmsPipelineFree(b2d);
    if (to) cmsFreeToneCurve(to);
    if (from) cmsFreeToneCurve(from);
    return ok;
}

// An absolute display profile (ICC.1:2001-04 for v2.4, ICC.1:2010 for v4.3): the TRCs include the
// black, the luminance tag holds the white in cd/m2, and v2 also carries the media white and
// black points as measured (v4 dropped the black point tag; its media white is D50 by rule).
csf_status build_icc(const csf_display_profile *p, int version, std::vector<unsigned char> &bytes, csf_error *err)
{
    cmsToneCurve *curve = icc_curve(p);
    if (!curve) return csf_error_set(err, CSF_E_NOMEM, "Little CMS could not build the tone curve");
    cmsToneCurve *curves[3] = {curve, curve, curve};
    cmsCIExyYTRIPLE prim;
    cmsCIExyY white;
    chromaticities(p, &prim, &white);
    cmsHPROFILE h = cmsCreateRGBProfile(&white, &prim, curves);
    cmsFreeToneCurve(curve);
    if (!h) return csf_error_set(err, CSF_E_FORMAT, "Little CMS could not build an RGB profile from these primaries");
    cmsSetProfileVersion(h, version == 2 ? 2.4 : 4.3);
    bool ok = write_text_tag(h, cmsSigProfileDescriptionTag, std::string("csfcal ") + csf_profile_id(p)) &&
              write_text_tag(h, cmsSigCopyrightTag, "No copyright claimed; written by csfcal");
    cmsCIEXYZ lumi = {0, csf_profile_lum_max(p), 0};
    ok = ok && cmsWriteTag(h, cmsSigLuminanceTag, &lumi);
    if (version == 2) {
        // v2 readers (ArgyllCMS) take absolute colorimetry from the media white and black points
        cmsCIEXYZ wtpt = xyY_to_XYZ(white), bkpt = wtpt;
        double yb = rel_lum(p, 0);
        bkpt.X *= yb;
        bkpt.Y *= yb;
        bkpt.Z *= yb;
        ok = ok && cmsWriteTag(h, cmsSigMediaWhitePointTag, &wtpt) && cmsWriteTag(h, cmsSigMediaBlackPointTag, &bkpt);
    } else {
        ok = ok && add_float_tags(h, p) && cmsMD5computeID(h);
    }
    cmsUInt32Number size = 0;
    ok = ok && cmsSaveProfileToMem(h, nullptr, &size) && size > 0;
    if (ok) {
        bytes.resize(size);
        ok = cmsSaveProfileToMem(h, bytes.data(), &size);
    }
    cmsCloseProfile(h);
    if (!ok) return csf_error_set(err, CSF_E_FORMAT, "Little CMS could not encode the ICC v%d profile", version);
    return CSF_OK;
}

csf_status write_icc(const csf_display_profile *p, int version, const char *path, csf_error *err)
{
    std::vector<unsigned char> bytes;
    csf_status st = build_icc(p, version, bytes, err);
    if (st) return st;
    return csf_write_file_atomic(path, "ICC profile", bytes.data(), bytes.size(), err);
}

csf_status eval_processor(OCIO::ConstCPUProcessorRcPtr cpu, const double *v, double *out, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        float px[3] = {(float)v[i], (float)v[i], (float)v[i]};
        cpu->applyRGB(px);
        out[i] = px[1];
    }
    return CSF_OK;
}

std::string dir_of(const char *path)
{
    std::string s(path);
    size_t slash = s.find_last_of('/');
    return slash == std::string::npos ? std::string(".") : s.substr(0, slash);
}

} // namespace

extern "C" {

int csf_export_format_from_name(const char *name)
{
    for (int i = 0; i < CSF_EXPORT_COUNT; i++)
        if (name && std::strcmp(name, kNames[i]) == 0) return i;
    return -1;
}

const char *csf_export_format_name(csf_export_format f)
{
    return (int)f >= 0 && f < CSF_EXPORT_COUNT ? kNames[f] : "?";
}

const char *csf_export_extension(csf_export_format f)
{
    return (int)f >= 0 && f < CSF_EXPORT_COUNT ? kExt[f] : "";
}

csf_status csf_colour_export(const csf_display_profile *p, csf_export_format f, const csf_export_options *opt,
                             const char *out_path, csf_error *err)
{
    if (!p || !out_path || !*out_path)
        return csf_error_set(err, CSF_E_INVALID_ARG, "export needs a profile and an output path");
    int icc_version = opt && opt->icc_version ? opt->icc_version : CSF_ICC_VERSION_DEFAULT;
    if (icc_version != 2 && icc_version != 4)
        return csf_error_set(err, CSF_E_INVALID_ARG, "ICC version %d: give 2 (v2.4) or 4 (v4.3)", icc_version);
    try {
        switch (f) {
        case CSF_EXPORT_CLF: return write_group(p, ".clf", out_path, err);
        case CSF_EXPORT_CTF: return write_group(p, ".ctf", out_path, err);
        case CSF_EXPORT_CUBE: return write_cube(p, out_path, err);
        case CSF_EXPORT_ICC: return write_icc(p, icc_version, out_path, err);
        case CSF_EXPORT_OCIO: return write_ocio(p, out_path, err);
        default: return csf_error_set(err, CSF_E_INVALID_ARG, "unknown export format %d", (int)f);
        }
    } catch (const std::exception &e) {
        return csf_error_set(err, CSF_E_FORMAT, "OpenColorIO refused the export to %s: %s", out_path, e.what());
    }
}

csf_status csf_colour_export_icc_cdm2(const char *path, const double *drive01, double *lum_cdm2, size_t n,
                                      double *white_cdm2, csf_error *err)
{
    cmsHPROFILE h = cmsOpenProfileFromFile(path, "r");
    if (!h) return csf_error_set(err, CSF_E_FORMAT, "Little CMS cannot read ICC profile %s", path);
    const cmsCIEXYZ *lumi = (const cmsCIEXYZ *)cmsReadTag(h, cmsSigLuminanceTag);
    if (!lumi || !(lumi->Y > 0)) {
        cmsCloseProfile(h);
        return csf_error_set(err, CSF_E_FORMAT, "ICC profile %s has no luminance tag (white in cd/m2)", path);
    }
    double white = lumi->Y;
    // relative colorimetric: PCS Y is luminance over the media white, black included in the TRCs
    cmsHPROFILE xyz = cmsCreateXYZProfile();
    cmsHTRANSFORM t = xyz ? cmsCreateTransform(h, TYPE_RGB_DBL, xyz, TYPE_XYZ_DBL, INTENT_RELATIVE_COLORIMETRIC,
                                               cmsFLAGS_NOCACHE) : nullptr;
    if (xyz) cmsCloseProfile(xyz);
    cmsCloseProfile(h);
    if (!t) return csf_error_set(err, CSF_E_FORMAT, "Little CMS cannot build a transform from ICC profile %s", path);
    for (size_t i = 0; i < n; i++) {
        double rgb[3] = {drive01[i], drive01[i], drive01[i]};
        cmsCIEXYZ out;
        cmsDoTransform(t, rgb, &out, 1);
        lum_cdm2[i] = out.Y * white;
    }
    cmsDeleteTransform(t);
    if (white_cdm2) *white_cdm2 = white;
    return CSF_OK;
}

csf_status csf_colour_export_eval(const char *path, csf_export_format f, const double *drive01,
                                  double *rel, size_t n, csf_error *err)
{
    try {
        if (f == CSF_EXPORT_ICC) {
            double white = 0;
            csf_status st = csf_colour_export_icc_cdm2(path, drive01, rel, n, &white, err);
            for (size_t i = 0; st == CSF_OK && i < n; i++) rel[i] /= white;
            return st;
        }
        OCIO::ConstProcessorRcPtr proc;
        if (f == CSF_EXPORT_OCIO) {
            OCIO::ConstConfigRcPtr cfg = OCIO::Config::CreateFromFile(path);
            proc = cfg->getProcessor("csfcal_display", "linear");
        } else {
            OCIO::ConfigRcPtr cfg = OCIO::Config::CreateRaw()->createEditableCopy();
            cfg->setSearchPath(dir_of(path).c_str());
            OCIO::FileTransformRcPtr ft = OCIO::FileTransform::Create();
            ft->setSrc(path);
            ft->setInterpolation(OCIO::INTERP_LINEAR);
            proc = cfg->getProcessor(ft);
        }
        return eval_processor(proc->getOptimizedCPUProcessor(OCIO::OPTIMIZATION_NONE), drive01, rel, n);
    } catch (const std::exception &e) {
        return csf_error_set(err, CSF_E_FORMAT, "OpenColorIO cannot read %s: %s", path, e.what());
    }
}

csf_status csf_colour_export_eval_icc_ocio(const char *path, const double *drive01, double *rel, size_t n,
                                           csf_error *err)
{
    try {
        OCIO::ConfigRcPtr cfg = OCIO::Config::CreateRaw()->createEditableCopy();
        cfg->setSearchPath(dir_of(path).c_str());
        OCIO::FileTransformRcPtr ft = OCIO::FileTransform::Create();
        ft->setSrc(path);
        // OpenColorIO's ICC transform goes from the PCS to device RGB; we want device -> PCS
        ft->setDirection(OCIO::TRANSFORM_DIR_INVERSE);
        OCIO::ConstProcessorRcPtr proc = cfg->getProcessor(ft);
        OCIO::ConstCPUProcessorRcPtr cpu = proc->getOptimizedCPUProcessor(OCIO::OPTIMIZATION_NONE);
        for (size_t i = 0; i < n; i++) {
            // device grey -> PCS XYZ (D50); Y of the white is 1
            float px[3] = {(float)drive01[i], (float)drive01[i], (float)drive01[i]};
            cpu->applyRGB(px);
            rel[i] = px[1];
        }
        return CSF_OK;
    } catch (const std::exception &e) {
        return csf_error_set(err, CSF_E_FORMAT, "OpenColorIO cannot read ICC profile %s: %s", path, e.what());
    }
}

} // extern "C"
