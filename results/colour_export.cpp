// Colour exports of a display profile (see results/colour_export.h). Thin: the curve comes from
// the profile, OpenColorIO writes and reads CLF/CTF/.cube/config, Little CMS writes and reads ICC.
// No exception crosses into C: every entry point catches and reports through csf_error.
// csfcal's C headers have no extern "C" guards of their own (except ours): give them C linkage.
extern "C" {
#include "results/csf_status.h"
#include "results/display_profile.h"
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

// Relative luminance of the grey curve at drive v: 0 at black, 1 at white.
double rel_lum(const csf_display_profile *p, double v)
{
    double b = csf_profile_lum_black(p), w = csf_profile_lum_max(p);
    return (csf_profile_grey_lum(p, v) - b) / (w - b);
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
    d << "csfcal display profile " << csf_profile_id(p) << ": drive (R=G=B) to relative luminance "
      << "(0 = " << csf_profile_lum_black(p) << " cd/m2, 1 = " << csf_profile_lum_max(p)
      << " cd/m2); measured " << csf_profile_created_utc(p) << " with " << csf_profile_instrument(p);
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
    lin->setDescription("relative display luminance, linear: 0 black, 1 white of the calibrated monitor");
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

csf_status write_text(const std::string &text, const char *path, csf_error *err)
{
    std::ofstream f(path, std::ios::binary);
    if (!f) return csf_error_set(err, CSF_E_IO, "cannot write %s: %s", path, std::strerror(errno));
    f << text;
    f.close();
    if (!f) return csf_error_set(err, CSF_E_IO, "cannot write %s", path);
    return CSF_OK;
}

csf_status write_group(const csf_display_profile *p, const char *ext, const char *path, csf_error *err)
{
    const char *fmt = write_format_name(ext);
    if (!fmt) return csf_error_set(err, CSF_E_UNSUPPORTED, "this OpenColorIO cannot write %s files", ext);
    OCIO::GroupTransformRcPtr g = OCIO::GroupTransform::Create();
    g->getFormatMetadata().addAttribute("id", csf_profile_id(p));
    g->getFormatMetadata().addChildElement(OCIO::METADATA_DESCRIPTION, describe(p).c_str());
    g->appendTransform(make_lut(p));
    std::ostringstream os;
    g->write(OCIO::Config::CreateRaw(), fmt, os);
    return write_text(os.str(), path, err);
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
    return write_text(os.str(), path, err);
}

csf_status write_ocio(const csf_display_profile *p, const char *path, csf_error *err)
{
    // the LUT goes beside the config, named after it, and is found through search_path "."
    std::string cfg_path(path);
    std::string base = cfg_path;
    size_t slash = base.find_last_of('/');
    std::string dir = slash == std::string::npos ? "" : base.substr(0, slash + 1);
    std::string name = slash == std::string::npos ? base : base.substr(slash + 1);
    size_t dot = name.find_last_of('.');
    if (dot != std::string::npos && dot > 0) name = name.substr(0, dot);
    std::string lut_name = name + ".clf";
    csf_status st = write_group(p, ".clf", (dir + lut_name).c_str(), err);
    if (st) return st;
    OCIO::ConfigRcPtr cfg = make_config(p, lut_name);
    cfg->validate(); // throws with OpenColorIO's reason if the config would not load
    std::ostringstream os;
    cfg->serialize(os);
    return write_text(os.str(), path, err);
}

csf_status write_icc(const csf_display_profile *p, const char *path, csf_error *err)
{
    std::vector<cmsFloat32Number> y(CSF_EXPORT_LUT_SIZE);
    for (int i = 0; i < CSF_EXPORT_LUT_SIZE; i++)
        y[i] = (cmsFloat32Number)rel_lum(p, (double)i / (CSF_EXPORT_LUT_SIZE - 1));
    cmsToneCurve *curve = cmsBuildTabulatedToneCurveFloat(nullptr, CSF_EXPORT_LUT_SIZE, y.data());
    if (!curve) return csf_error_set(err, CSF_E_NOMEM, "Little CMS could not build the tone curve");
    cmsToneCurve *curves[3] = {curve, curve, curve};
    // primaries from the measured XYZ when known, else sRGB/Rec.709 (facts of the standard)
    cmsCIExyYTRIPLE prim = {{0.64, 0.33, 1}, {0.30, 0.60, 1}, {0.15, 0.06, 1}};
    cmsCIExyY white = {0.3127, 0.3290, 1};
    double rgbw[4][3];
    if (csf_profile_primaries_xyz(p, rgbw)) {
        cmsCIExyY *dst[4] = {&prim.Red, &prim.Green, &prim.Blue, &white};
        bool ok = true;
        for (int s = 0; s < 4; s++) {
            double sum = rgbw[s][0] + rgbw[s][1] + rgbw[s][2];
            if (!(sum > 0) || !(rgbw[s][1] > 0)) ok = false;
        }
        if (ok)
            for (int s = 0; s < 4; s++) {
                double sum = rgbw[s][0] + rgbw[s][1] + rgbw[s][2];
                dst[s]->x = rgbw[s][0] / sum;
                dst[s]->y = rgbw[s][1] / sum;
                dst[s]->Y = 1;
            }
    }
    cmsHPROFILE h = cmsCreateRGBProfile(&white, &prim, curves);
    cmsFreeToneCurve(curve);
    if (!h) return csf_error_set(err, CSF_E_FORMAT, "Little CMS could not build an RGB profile from these primaries");
    cmsSetProfileVersion(h, 4.3);
    cmsMLU *desc = cmsMLUalloc(nullptr, 1);
    std::string d = std::string("csfcal ") + csf_profile_id(p);
    cmsMLUsetASCII(desc, "en", "US", d.c_str());
    cmsWriteTag(h, cmsSigProfileDescriptionTag, desc);
    cmsMLUfree(desc);
    cmsCIEXYZ lumi = {0, csf_profile_lum_max(p), 0};
    cmsWriteTag(h, cmsSigLuminanceTag, &lumi);
    bool ok = cmsSaveProfileToFile(h, path);
    cmsCloseProfile(h);
    if (!ok) return csf_error_set(err, CSF_E_IO, "cannot write ICC profile %s", path);
    return CSF_OK;
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

csf_status csf_colour_export(const csf_display_profile *p, csf_export_format f, const char *out_path,
                             csf_error *err)
{
    if (!p || !out_path || !*out_path)
        return csf_error_set(err, CSF_E_INVALID_ARG, "export needs a profile and an output path");
    try {
        switch (f) {
        case CSF_EXPORT_CLF: return write_group(p, ".clf", out_path, err);
        case CSF_EXPORT_CTF: return write_group(p, ".ctf", out_path, err);
        case CSF_EXPORT_CUBE: return write_cube(p, out_path, err);
        case CSF_EXPORT_ICC: return write_icc(p, out_path, err);
        case CSF_EXPORT_OCIO: return write_ocio(p, out_path, err);
        default: return csf_error_set(err, CSF_E_INVALID_ARG, "unknown export format %d", (int)f);
        }
    } catch (const std::exception &e) {
        return csf_error_set(err, CSF_E_FORMAT, "OpenColorIO refused the export to %s: %s", out_path, e.what());
    }
}

csf_status csf_colour_export_eval(const char *path, csf_export_format f, const double *drive01,
                                  double *rel, size_t n, csf_error *err)
{
    try {
        if (f == CSF_EXPORT_ICC) {
            cmsHPROFILE h = cmsOpenProfileFromFile(path, "r");
            if (!h) return csf_error_set(err, CSF_E_FORMAT, "Little CMS cannot read ICC profile %s", path);
            cmsToneCurve *c = (cmsToneCurve *)cmsReadTag(h, cmsSigGreenTRCTag);
            if (!c) {
                cmsCloseProfile(h);
                return csf_error_set(err, CSF_E_FORMAT, "ICC profile %s has no green TRC", path);
            }
            // evaluate the stored 16-bit table in double: cmsEvalToneCurveFloat would also
            // quantise the input to 16 bits, adding an error the file itself does not have
            cmsUInt32Number ne = cmsGetToneCurveEstimatedTableEntries(c);
            const cmsUInt16Number *tab = cmsGetToneCurveEstimatedTable(c);
            if (ne < 2 || !tab) {
                cmsCloseProfile(h);
                return csf_error_set(err, CSF_E_FORMAT, "ICC profile %s: green TRC has no table", path);
            }
            for (size_t i = 0; i < n; i++) {
                double x = drive01[i] < 0 ? 0 : drive01[i] > 1 ? 1 : drive01[i];
                double pos = x * (ne - 1);
                cmsUInt32Number k = (cmsUInt32Number)pos;
                if (k >= ne - 1) k = ne - 2;
                double f = pos - k;
                rel[i] = (tab[k] + f * (tab[k + 1] - tab[k])) / 65535.0;
            }
            cmsCloseProfile(h);
            return CSF_OK;
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
