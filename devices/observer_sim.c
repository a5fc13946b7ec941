/* placeholder: filled in by its area */
typedef int csf_placeholder_observer_sim;
