/PROG  CALIB_SPH
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "sphere poses";
DEFAULT_GROUP	= 1,*,*,*,*;
/MN
   1:  UFRAME_NUM=0 ;
   2:  UTOOL_NUM=0 ;
   3:J P[1] 20% FINE    ;
   4:J P[2] 20% FINE    ;
   5:J P[3] 20% FINE    ;
   6:J P[4] 20% FINE    ;
   7:J P[5] 20% FINE    ;
   8:J P[6] 20% FINE    ;
   9:J P[7] 20% FINE    ;
  10:J P[8] 20% FINE    ;
  11:J P[9] 20% FINE    ;
  12:J P[10] 20% FINE    ;
  13:J P[11] 20% FINE    ;
  14:J P[12] 20% FINE    ;
  15:J P[13] 20% FINE    ;
  16:J P[14] 20% FINE    ;
  17:J P[15] 20% FINE    ;
/POS
P[1]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =   -195.800  mm,	Y =   1363.305  mm,	Z =    524.812  mm,
	W =   -179.924 deg,	P =      0.889 deg,	R =    179.635 deg
};
P[2]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =   -185.745  mm,	Y =   1363.314  mm,	Z =    524.772  mm,
	W =   -179.923 deg,	P =      0.889 deg,	R =    179.636 deg
};
P[3]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =   -168.275  mm,	Y =   1363.317  mm,	Z =    524.723  mm,
	W =   -179.921 deg,	P =      0.890 deg,	R =    179.636 deg
};
P[4]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =   -195.773  mm,	Y =   1363.322  mm,	Z =    543.692  mm,
	W =   -179.920 deg,	P =      0.890 deg,	R =    179.634 deg
};
P[5]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =   -195.702  mm,	Y =   1399.586  mm,	Z =    543.602  mm,
	W =   -179.917 deg,	P =      0.891 deg,	R =    179.631 deg
};
P[6]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =   -195.686  mm,	Y =   1312.404  mm,	Z =    543.563  mm,
	W =   -179.915 deg,	P =      0.891 deg,	R =    179.631 deg
};
P[7]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =   -195.748  mm,	Y =   1318.007  mm,	Z =    471.161  mm,
	W =    175.932 deg,	P =      0.861 deg,	R =    179.570 deg
};
P[8]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =   -195.734  mm,	Y =   1296.468  mm,	Z =    431.460  mm,
	W =    172.155 deg,	P =      0.831 deg,	R =    179.513 deg
};
P[9]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =   -195.684  mm,	Y =   1247.878  mm,	Z =    357.626  mm,
	W =    166.888 deg,	P =      0.784 deg,	R =    179.436 deg
};
P[10]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =   -134.814  mm,	Y =   1363.333  mm,	Z =    540.547  mm,
	W =   -179.882 deg,	P =     -5.178 deg,	R =    179.634 deg
};
P[11]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =   -105.124  mm,	Y =   1363.341  mm,	Z =    540.496  mm,
	W =   -179.858 deg,	P =     -8.602 deg,	R =    179.631 deg
};
P[12]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =    -69.126  mm,	Y =   1363.347  mm,	Z =    540.446  mm,
	W =   -179.829 deg,	P =    -12.721 deg,	R =    179.626 deg
};
P[13]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =   -117.498  mm,	Y =   1359.710  mm,	Z =    524.746  mm,
	W =   -179.922 deg,	P =      0.889 deg,	R =   -174.125 deg
};
P[14]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =    -69.786  mm,	Y =   1359.718  mm,	Z =    524.694  mm,
	W =   -179.920 deg,	P =      0.889 deg,	R =   -170.688 deg
};
P[15]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =    -12.159  mm,	Y =   1349.104  mm,	Z =    524.655  mm,
	W =   -179.918 deg,	P =      0.888 deg,	R =   -165.374 deg
};
/END
