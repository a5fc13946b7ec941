csfcal-display-profile 1
# luminance per drive value of one monitor; see docs/display-profile.md
id = sim-display-lcd-20261122-7b47c972
display = sim:display=lcd
instrument = csfcal simulated photometer (display=lcd, noise=0.0005, abs_noise=0.001 cd/m2, integration 0.5 s)
created_utc = 2026-11-22T05:52:53Z
tool_version = 0.1.0
lum_black_cdm2 = 0.34981657305021424
lum_max_cdm2 = 180.31111241693847
additivity_error = 0.030725146687240912
has_channels = 1
primary_r_xyz = 76.599834113766363,39.497541397976427,3.5919917404342088
primary_g_xyz = 66.311993337189335,132.60697529109413,22.1069786707826