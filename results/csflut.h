/* placeholder: csflut public header */
#ifndef CSFLUT_H
#define CSFLUT_H
#endif
