<?xml version="1.0" encoding="UTF-8"?>
<!DOCTYPE core:CityModel [ <!ENTITY xxe SYSTEM "file:///etc/passwd"> ]>
<core:CityModel xmlns:core="http://www.opengis.net/citygml/2.0" xmlns:bldg="http://www.opengis.net/citygml/building/2.0" xmlns:gml="http://www.opengis.net/gml" xmlns:xlink="http://www.w3.org/1999/xlink">
<gml:boundedBy><gml:Envelope srsName="EPSG:25832" srsDimension="3"><gml:lowerCorner>400000 5860000 40</gml:lowerCorner><gml:upperCorner>400100 5860100 48</gml:upperCorner></gml:Envelope></gml:boundedBy>
<core:cityObjectMember><bldg:Building gml:id="&xxe;"><bldg:lod1Solid><gml:Solid><gml:exterior><gml:CompositeSurface>
<gml:surfaceMember><gml:Polygon><gml:exterior><gml:LinearRing><gml:posList srsDimension="3">400000.0 5860000.0 40.0 400000.0 5860008.0 40.0 400010.0 5860008.0 40.0 400010.0 5860000.0 40.0 400000.0 5860000.0 40.0</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon></gml:surfaceMember>
<gml:surfaceMember><gml:Polygon><gml:exterior><gml:LinearRing><gml:posList srsDimension="3">400000.0 5860000.0 48.0 400010.0 5860000.0 48.0 400010.0 5860008.0 48.0 400000.0 5860008.0 48.0 400000.0 5860000.0 48.0</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon></gml:surfaceMember>
<gml:surfaceMember><gml:Polygon><gml:exterior><gml:LinearRing><gml:posList srsDimension="3">400000.0 5860000.0 40.0 400010.0 5860000.0 40.0 400010.0 5860000.0 48.0 400000.0 5860000.0 48.0 400000.0 5860000.0 40.0</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon></gml:surfaceMember>
<gml:surfaceMember><gml:Polygon><gml:exterior><gml:LinearRing><gml:posList srsDimension="3">400010.0 5860000.0 40.0 400010.0 5860008.0 40.0 400010.0 5860008.0 48.0 400010.0 5860000.0 48.0 400010.0 5860000.0 40.0</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon></gml:surfaceMember>
<gml:surfaceMember><gml:Polygon><gml:exterior><gml:LinearRing><gml:posList srsDimension="3">400010.0 5860008.0 40.0 400000.0 5860008.0 40.0 400000.0 5860008.0 48.0 400010.0 5860008.0 48.0 400010.0 5860008.0 40.0</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon></gml:surfaceMember>
<gml:surfaceMember><gml:Polygon><gml:exterior><gml:LinearRing><gml:posList srsDimension="3">400000.0 5860008.0 40.0 400000.0 5860000.0 40.0 400000.0 5860000.0 48.0 400000.0 5860008.0 48.0 400000.0 5860008.0 40.0</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon></gml:surfaceMember>
</gml:CompositeSurface></gml:exterior></gml:Solid></bldg:lod1Solid></bldg:Building></core:cityObjectMember>
</core:CityModel>
