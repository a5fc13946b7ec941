/* placeholder: joint Bayesian procedure (owner: bayes) */
typedef int csf_placeholder_method_bayes;
