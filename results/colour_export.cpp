// placeholder: filled in by its area
namespace csf_placeholder {}
