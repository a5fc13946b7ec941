/* placeholder: filled in by its area */
typedef int csf_placeholder_plot;
