csfcal-display-profile 1
[curve grey]
transform_gamma = 2
drive01,lum_cdm2
0,5
1,2
