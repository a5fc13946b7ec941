/* placeholder */
typedef int csflut_placeholder_b;
